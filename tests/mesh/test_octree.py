"""Octrees refined around shapes and balanced: vertex balance against edge balance, a shape that misses the
domain.  The cells a shape meets: test_refinement; a tree brought as leaves: test_leaf_list; the arrays: test_tree."""

from __future__ import annotations


import pytest

from cospherical.core.configuration import Box
from cospherical.mesh.octree import build_octree, parse_shape

CUBE = Box.parse(["1", "1", "1"])
UNIT = Box.parse([1, 1, 1])


def test_vertex_balance_is_never_coarser_than_edge_balance():
    shapes = [parse_shape("point:0.3,0.61,0.77")]
    assert len(build_octree(CUBE, 6, shapes, "vertex")) >= len(build_octree(CUBE, 6, shapes, "edge"))


@pytest.mark.parametrize("shape, outside", [
    ("point:2,0.5,0.5", True), ("point:0.5,0.5,-0.001", True), ("box:1.01,0,0,2,1,1", True),
    ("sphere:3,3,3,1", True), ("sphere:0.5,0.5,0.5,5", True),  # a sphere around the whole domain meets none of it
    ("plane:1,0,0,1.5", True), ("plane:0,0,1,-1/3", True),
    ("point:1,1,1", False), ("box:1,0,0,2,1,1", False), ("sphere:2,0.5,0.5,1", False),  # touching counts
    ("plane:1,1,1,3", False), ("sphere:0.5,0.5,0.5,0.2", False),
])
def test_a_shape_that_does_not_meet_the_domain_warns_once(shape, outside):
    import warnings

    from cospherical.errors import CosphericalWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        tree = build_octree(UNIT, 2, [parse_shape(shape), parse_shape("point:0.1,0.1,0.1")])
    said = [str(w.message) for w in caught if issubclass(w.category, CosphericalWarning)]
    assert said == ([f"refine shape {shape!r} does not meet the domain: it refines nothing"] if outside else [])
    alone = build_octree(UNIT, 2, [parse_shape("point:0.1,0.1,0.1")])
    assert (len(tree) == len(alone)) == outside or not outside and len(tree) >= len(alone)
