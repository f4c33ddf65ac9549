"""Tessellations whose answer is known by hand, and properties every tessellation must have, checked on
generated configurations."""

from __future__ import annotations

from collections import Counter
from fractions import Fraction

import networkx as nx
import pytest
from hypothesis import HealthCheck, given, settings
from sampling import examples
from strategies import configurations

from cospherical import Configuration, tessellate


def names(code, box=("1", "1", "1"), policy="octree"):
    return Counter(e.type.name for e in tessellate(Configuration.from_code(code, box, policy)).elements)


def test_plain_box_is_one_cuboid():
    tess = tessellate(Configuration.from_code("000000000000", ("1", "2", "4")))
    (element,) = tess.elements
    assert element.type.name == "Cuboid" and element.nodes == (0, 1, 2, 3, 4, 5, 6, 7)
    assert element.polyhedron.center == (Fraction(1, 2),) * 3
    assert tess.circumcenter(element) == (0.5, 1.0, 2.0)


def test_one_midpoint_gives_four_pyramids():
    assert names("800000000000") == {"Rectangular Pyramid": 4}


def test_all_midpoints_with_octree_points_give_eight_cuboids():
    assert names("888888888888") == {"Cuboid": 8}
    assert names("888888888888", ("1", "2", "4")) == {"Cuboid": 8}


def test_exact_sqrt2_differs_from_rounded():
    # More points become co-spherical at exactly sqrt(2): fewer, larger elements.
    exact = tessellate(Configuration.from_code("880000000000", ("1", "sqrt(2)", "sqrt(2)")))
    rounded = tessellate(Configuration.from_code("880000000000", ("1", "1.4142", "1.4142")))
    assert len(exact.elements) < len(rounded.elements)


def test_fvm_closed_and_open_box():
    # On a 1 x 2 x 4 box with midpoints on the long edges, circumcenters leave the box.
    tess = tessellate(Configuration.from_code("000000008888", ("4", "2", "1")))
    assert tess.fvm_adequate == all(all(0 <= x <= 1 for x in e.polyhedron.center) for e in tess.elements)
    plain = tessellate(Configuration.from_code("000000000000"))
    assert plain.fvm_adequate and plain.fvm_adequate_open


# 100 random configurations a run (each run draws new ones), 150 with --full
SETTINGS = settings(max_examples=examples(150), deadline=None, suppress_health_check=[HealthCheck.too_slow])


def squared_distance(p, q, squared_lengths) -> Fraction:
    # Independent of the integer frame: plain Fractions in real units squared.
    return sum(w * (x - y) ** 2 for w, x, y in zip(squared_lengths, p, q))


@pytest.mark.oracle_networkx
@SETTINGS
@given(configurations())
def test_cells_tile_the_box_face_to_face_with_empty_spheres_and_planar_faces(cfg):
    # One tessellation per drawn configuration, each property checked on it (four tests drawing their own
    # configurations tessellated each one again: 4 x the CPU for the same properties).
    tess = tessellate(cfg)
    assert sum(e.polyhedron.unit_volume for e in tess.elements) == 1, "volumes do not sum to the box"
    check_every_sphere_is_empty_and_passes_through_its_cell(cfg, tess)
    check_cells_meet_face_to_face(tess)
    check_euler_formula_and_planar_embedding(tess)


def check_every_sphere_is_empty_and_passes_through_its_cell(cfg, tess):
    squared = cfg.box.squared
    for e in tess.elements:
        center = e.polyhedron.center
        radius = {squared_distance(tess.nodes[v], center, squared) for v in e.polyhedron.nodes}
        assert len(radius) == 1, "cell vertices not co-spherical"
        (r2,) = radius
        for node, point in tess.nodes.items():
            d2 = squared_distance(point, center, squared)
            assert d2 >= r2, f"node {node} strictly inside the sphere of {e.nodes}"
            assert (d2 == r2) == (node in e.polyhedron.nodes), f"node {node} on the sphere but not in the cell"


def _on_box_boundary(face, nodes) -> bool:
    return any(len({nodes[v][axis] for v in face}) == 1 and nodes[face[0]][axis] in (0, 1) for axis in range(3))


def check_cells_meet_face_to_face(tess):
    uses = Counter()
    directed = set()
    for e in tess.elements:
        for face in e.polyhedron.faces:
            uses[frozenset(face)] += 1
            directed.update((face[i], face[(i + 1) % len(face)]) for i in range(len(face)))
    for face, count in uses.items():
        if count == 1:
            assert _on_box_boundary(tuple(face), tess.nodes), f"face {sorted(face)} is free inside the box"
        else:
            assert count == 2, f"face {sorted(face)} shared by {count} cells"
    # A shared face is walked in opposite directions by its two cells.
    for e in tess.elements:
        for face in e.polyhedron.faces:
            if uses[frozenset(face)] == 2:
                assert all((face[(i + 1) % len(face)], face[i]) in directed for i in range(len(face)))


def check_euler_formula_and_planar_embedding(tess):
    for e in tess.elements:
        v, edges, f = e.polyhedron.counts
        assert v - edges + f == 2
        assert (v, edges, f) == (e.type.vertices, e.type.edges, e.type.faces)
        embedding_of(e.polyhedron.faces).check_structure()


def embedding_of(faces) -> nx.PlanarEmbedding:
    """The faces (counter-clockwise from outside) as a networkx rotation system."""
    turn = {}
    for face in faces:
        n = len(face)
        for i in range(n):
            turn[face[i], face[(i + 1) % n]] = face[i - 1]  # next neighbour counter-clockwise
    embedding = nx.PlanarEmbedding()
    for node in {v for face in faces for v in face}:
        first = next(w for (u, w) in turn if u == node)
        embedding.add_half_edge(node, first)
        previous, w = first, turn[node, first]
        while w != first:
            embedding.add_half_edge(node, w, cw=previous)
            previous, w = w, turn[node, w]
    return embedding


@SETTINGS
@given(configurations(dyadic=True))
def test_nodes_follow_the_numbering(cfg):
    tess = tessellate(cfg)
    for k, t in enumerate(cfg.steiner):
        assert (8 + k in tess.nodes) == (t is not None)
    used = {v for e in tess.elements for v in e.nodes}
    assert used == set(tess.nodes), "every point is a vertex of some cell"
    assert Configuration.from_code(cfg.code, cfg.box, cfg.face_points) == cfg
