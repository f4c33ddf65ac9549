"""Splits of a cell into cospherical pieces: the internal-face search is the internal-edge search without
inner edges, and the boundary pre-check rejects only what the hull test rejects."""

from __future__ import annotations

from cospherical.catalogue import element_options


def test_internal_face_splits_are_the_internal_edge_splits_without_inner_edges(paper_studies):
    # split_options filters the internal-edge search for the internal-face criterion:
    # the filter must give exactly what the criterion's own search gives.
    from cospherical.core.geometry import Frame
    from cospherical.core.split import subdivisions

    seen = set()
    for study in paper_studies.values():
        for tess in study.tessellations.values():
            for element in tess.elements:
                points = {n: tess.nodes[n] for n in element.polyhedron.nodes}
                key = (tuple(sorted(points.items())), tess.configuration.box.squared)
                if key in seen:
                    continue
                seen.add(key)
                own = subdivisions(Frame.build(points, tess.configuration.box.squared), element.polyhedron,
                                   "internal_faces")
                filtered = element_options(tess, element, "internal_faces")
                assert sorted(tuple(p.nodes for p in split) for split in own) == sorted(
                    tuple(p.polyhedron.nodes for p in option) for option in filtered)


def test_boundary_precheck_rejects_only_what_the_hull_test_rejects(paper_studies):
    # The split search skips the hull of a candidate that shares three or more but
    # not all vertices of a boundary face: the hull test must reject each such one.
    from itertools import combinations

    from cospherical.core.delaunay import hull_faces
    from cospherical.core.geometry import Frame
    from cospherical.core.split import _Element

    seen = set()
    skipped = 0
    for study in paper_studies.values():
        for tess in study.tessellations.values():
            for element in tess.elements:
                points = {n: tess.nodes[n] for n in element.polyhedron.nodes}
                key = (tuple(sorted(points.items())), tess.configuration.box.squared)
                if len(points) == 4 or key in seen:
                    continue
                seen.add(key)
                own = _Element(Frame.build(points, tess.configuration.box.squared), element.polyhedron,
                               "internal_edges_and_faces")
                for size in range(4, len(points) + 1):
                    for subset in combinations(own.members, size):
                        if not own._cuts_boundary(frozenset(subset)):
                            continue
                        skipped += 1
                        try:
                            faces = hull_faces(own.frame, list(subset))
                        except ValueError:
                            continue
                        assert own._check(faces) is None
    assert skipped > 1000
