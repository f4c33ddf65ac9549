"""Octrees refined around shapes, under edge and vertex balance."""

from __future__ import annotations

from cospherical.core.configuration import Box
from cospherical.mesh.octree import build_octree, parse_shape

CUBE = Box.parse(["1", "1", "1"])


def test_vertex_balance_is_never_coarser_than_edge_balance():
    shapes = [parse_shape("point:0.3,0.61,0.77")]
    assert len(build_octree(CUBE, 6, shapes, "vertex")) >= len(build_octree(CUBE, 6, shapes, "edge"))
