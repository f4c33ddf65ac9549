"""The global Delaunay (empty-sphere) check against a brute force, and the tree's structure against a k-d tree's search."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from hypothesis import HealthCheck, given, settings

from cospherical.core.configuration import Box
from cospherical.mesh.assembly import assemble
from cospherical.mesh.checks import check_circumcenters, check_delaunay
from cospherical.mesh.checks.empty_sphere import _local_candidates, _spheres
from cospherical.mesh.octree import build_octree, parse_shape

from ..test_dual import octrees

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
