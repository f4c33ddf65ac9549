"""The exact whole-mesh checks against a brute force."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from hypothesis import HealthCheck, given, settings

from cospherical.core.configuration import Box
from cospherical.mesh.assembly import assemble
from cospherical.mesh.checks import _spheres, check_circumcenters, check_delaunay
from cospherical.mesh.octree import build_octree, parse_shape

from .test_dual import octrees

BRICK = Box.parse(["1", "2", "4"])


def test_global_delaunay_equals_brute_force_on_a_brick():
    """The 1x2x4 octree is not globally Delaunay; the exact check agrees with brute force over all vertices."""
    mesh = assemble(build_octree(BRICK, 4, [parse_shape("sphere:0.5,1,2,0.6")]))
    found = check_delaunay(mesh)
    conn, sizes = mesh.connectivity()
    points = mesh.vertices * (np.array(BRICK.to_float()) / mesh.grid)
    pairs = elements = 0
    for e in range(len(mesh)):
        nodes = conn[e, :sizes[e]]
        x = points[nodes]
        center = np.linalg.lstsq(2 * (x[1:] - x[0]), (x[1:] ** 2).sum(1) - (x[0] ** 2).sum(), rcond=None)[0]
        d2 = ((points - center) ** 2).sum(1)
        d2[nodes] = np.inf
        inside = int((d2 < ((x[0] - center) ** 2).sum() * (1 - 1e-9)).sum())
        pairs, elements = pairs + inside, elements + (inside > 0)
    assert (found.violating_pairs, found.violations) == (pairs, elements)
    assert found.violations > 0 and len(found.violating_elements) == found.violations
    assert check_circumcenters(mesh).leaves_not_fvm_adequate > 0


def _shapes(vertices: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """Each element's class of translates, node for node (what check computes from a dual's elements)."""
    coords = np.where((conn >= 0)[..., None], vertices[np.maximum(conn, 0)], 0)
    relative = np.where((conn >= 0)[..., None], coords - coords[:, :1], -1).reshape(len(conn), -1)
    return np.unique(relative, axis=0, return_inverse=True)[1].reshape(-1)


def test_faces_of_elements_given_by_their_vertices_pair_as_the_meshs_own():
    """The faces check computes from bare element lists (a dual's) pair exactly as the mesh's own faces do:
    same interior pairs and boundary faces; and faces that would take more memory than allowed are
    refused before any is made."""
    import pytest

    from cospherical.errors import InputError
    from cospherical.mesh.checks import check_conformity, element_faces, pair_faces

    mesh = assemble(build_octree(BRICK, 3, [parse_shape("sphere:0.5,1,2,0.6")]))
    conn, sizes = mesh.connectivity()
    shape = _shapes(mesh.vertices, conn)
    faces = element_faces(mesh.vertices, conn, sizes, shape, BRICK.squared)
    needed = sum(rows.nbytes for parts in faces.values() for rows in parts)
    found = pair_faces(faces, mesh.vertices, mesh.grid)
    own = check_conformity(mesh)
    assert found == own and own.nonconforming_faces == 0 and own.interior_faces > 0
    # one element's nodes moved to another's: the faces no longer pair
    conn[3] = conn[200]
    broken = pair_faces(element_faces(mesh.vertices, conn, sizes, _shapes(mesh.vertices, conn), BRICK.squared),
                        mesh.vertices, mesh.grid)
    assert broken.nonconforming_faces > 0
    with pytest.raises(InputError, match="faces need"):
        element_faces(mesh.vertices, conn, sizes, shape, BRICK.squared, most_bytes=needed)


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(octrees())
def test_bare_element_lists_pair_as_the_mesh_on_any_octree(mesh):
    from cospherical.mesh.checks import check_conformity, element_faces, pair_faces

    conn, sizes = mesh.connectivity()
    faces = element_faces(mesh.vertices, conn, sizes, _shapes(mesh.vertices, conn), mesh.box.squared)
    assert pair_faces(faces, mesh.vertices, mesh.grid) == check_conformity(mesh)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(octrees())
def test_the_trees_structure_finds_what_the_search_finds(mesh):
    """On a vertex-balanced tree the Delaunay check looks up the few grid points that can lie on or in a leaf
    element's sphere instead of searching; a k-d tree's search over every vertex (the same mesh, its tree
    not claimed balanced) finds the same violations, ties and elements that are not cells."""
    assert mesh.tree.vertex_balanced
    # a leaf's sphere reaches less than 3/4 of the leaf beyond it in a cube (not across the short sides of a brick)
    if mesh.box.squared == (1, 1, 1):
        assert len(_spheres(mesh)[0].searched) < len(mesh)
    mine = check_delaunay(mesh)
    theirs = check_delaunay(replace(mesh, tree=replace(mesh.tree, vertex_balanced=False), _groups=None))
    assert (mine.violations, mine.violating_pairs, mine.violating_leaves, mine.ties) == \
        (theirs.violations, theirs.violating_pairs, theirs.violating_leaves, theirs.ties)
    for name in ("violating_leaf_ids", "violating_elements", "not_cells"):
        assert np.array_equal(getattr(mine, name), getattr(theirs, name)), name


def test_the_lattice_at_half_a_leaf_is_looked_up_on_a_tree_and_on_a_part_of_it():
    """Spheres of a brick's leaf elements reach half a leaf beyond the leaf: there the look-up of the quarter-leaf
    lattice must find the vertices of smaller neighbours that violate (random cube trees never need it, their
    spheres stay within 3/8 of a leaf).  The whole tree, and the part a device would keep with one octant of the
    box dropped, agree with the k-d tree's search in every figure, and their look-ups did find lattice vertices."""
    from cospherical.mesh.checks import _local_candidates
    from cospherical.mesh.octree import Octree

    tree = build_octree(BRICK, 4, [parse_shape("point:0.1,0.1,0.1")])
    octant = ((tree.positions >> (tree.levels.astype(np.int64) - 1)[:, None]) == (1, 0, 0)).all(axis=1)
    for part in (tree, Octree(tree.box, tree.levels[~octant], tree.positions[~octant], tree.vertex_balanced)):
        mesh = assemble(part)
        looked_up, _ = _local_candidates(mesh, _spheres(mesh)[1])
        assert len(looked_up) > 0
        mine = check_delaunay(mesh)
        theirs = check_delaunay(replace(mesh, tree=replace(mesh.tree, vertex_balanced=False), _groups=None))
        assert mine.violations > 0
        assert (mine.violations, mine.violating_pairs, mine.violating_leaves, mine.ties) == \
            (theirs.violations, theirs.violating_pairs, theirs.violating_leaves, theirs.ties)
        for name in ("violating_leaf_ids", "violating_elements", "not_cells"):
            assert np.array_equal(getattr(mine, name), getattr(theirs, name)), name


def test_only_vertex_balance_claims_the_structure():
    """The check's bound on where vertices lie holds for trees balanced across corners too, not across edges only."""
    shapes = [parse_shape("point:0.1,0.1,2")]
    assert build_octree(BRICK, 3, shapes).vertex_balanced and not build_octree(BRICK, 3, shapes, "edge").vertex_balanced


def test_a_point_is_in_the_closed_union_of_boxes_exactly():
    """Where a device's circumcentres may lie: an L's notch is outside, its walls and re-entrant edge inside
    (against the boxes, in Fractions)."""
    from fractions import Fraction

    from cospherical.mesh.checks import in_closed_domain
    from cospherical.mesh.device import Device, Region, device_layout

    def box(*values):
        return tuple(Fraction(v) for v in values)

    layout = device_layout(Device("l", (Region("a", "Si", (box(0, 0, 0, 2, 1, 1), box(0, 1, 0, 1, 2, 1))),), (),
                                  (), 1))
    grid = 8  # grid units: the L is the boxes (0, 0, 0)-(8, 4, 8) and (0, 4, 0)-(4, 8, 8)
    boxes = [(0, 0, 0, 8, 4, 8), (0, 4, 0, 4, 8, 8)]
    third = Fraction(1, 3)
    points = [(5, 5, 1), (4, 5, 1), (5, 4, 1), (4, 4, 8), (4 + third, 4 + third, 1), (8, 4, 0), (8 + third, 1, 1),
              (1, 8, 8), (4 - third, 8, third), (4 + third, 8, 1), (2, 2, -third)]
    want = [any(all(b[a] <= p[a] <= b[a + 3] for a in range(3)) for b in boxes) for p in points]
    num = np.array([[int(Fraction(x) * 3) for x in p] for p in points], dtype=np.int64)
    assert in_closed_domain(num, np.full((len(num), 1), 3, dtype=np.int64), grid, layout).tolist() == want
    assert sum(want) not in (0, len(want))
