"""Tetrahedra merged into cells: shapes measured once up to scale, points located in leaves exactly."""

from __future__ import annotations

import numpy as np

from cospherical.core.configuration import Box
from cospherical.mesh.assembly import assemble
from cospherical.mesh.delaunay import global_delaunay
from cospherical.mesh.merged_cells import Locator, cell_shape, scaled_shape
from cospherical.mesh.octree import build_octree, parse_shape


def test_a_scaled_cell_shape_is_the_shape_of_the_scaled_offsets():
    # shapes are classified once up to scale; the scaled copy must be what a direct measurement gives
    mesh = global_delaunay(assemble(build_octree(Box.parse(["1", "2", "4"]), 3, [parse_shape("point:0.1,0.1,0.1")])))
    for shape in mesh.cells.shapes[:6]:
        unit, _ = cell_shape(list(shape.offsets), mesh.box.squared, {}, mesh.catalogue)
        for g in (2, 3):
            direct, _ = cell_shape([tuple(g * x for x in o) for o in shape.offsets], mesh.box.squared, {},
                                   mesh.catalogue)
            assert scaled_shape(unit, g) == direct


def test_the_locator_finds_the_leaf_whose_closed_box_holds_a_point():
    mesh = assemble(build_octree(Box.parse(["1", "1", "1"]), 2, [parse_shape("point:0.1,0.1,0.1")]))
    size = mesh.leaf_size()
    low = mesh.tree.positions.astype(np.int64) * size[:, None]
    # each leaf's center (4 x grid coordinates), and the points found there against the boxes by hand
    centers = 4 * low + 2 * size[:, None]
    found = Locator(mesh).leaf(centers)
    assert np.array_equal(found, np.arange(len(mesh.tree)))
    corner = Locator(mesh).leaf(np.array([[4 * mesh.grid] * 3]))  # the domain's far corner: in the closed domain
    assert np.all(4 * (low[corner] + size[corner, None]) == 4 * mesh.grid)
