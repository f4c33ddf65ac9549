"""``cospherical.from_treemesh``: a discretize.TreeMesh meshed as it is, its nodes the mesh's vertices."""

from __future__ import annotations

import warnings

import discretize
import numpy as np
import pytest

import cospherical
from cospherical.errors import InputError

pytestmark = pytest.mark.oracle_discretize


def _rows(points: np.ndarray) -> np.ndarray:
    return np.unique(np.round(points, 12), axis=0)


@pytest.mark.parametrize("cells, origin", [((1 / 16, 16), (0, 0, 0)), ((0.25, 8), (1.0, -2.0, 3.5))])
def test_the_vertices_are_discretizes_nodes(cells, origin):
    tree_mesh = discretize.TreeMesh([[cells]] * 3, origin=origin, diagonal_balance=True)
    corner = np.array(origin) + 0.3 * cells[0] * cells[1]
    tree_mesh.refine_points([corner], level=tree_mesh.max_level, padding_cells_by_level=[1] * tree_mesh.max_level)
    m = cospherical.from_treemesh(tree_mesh, uniform=False)
    assert len(m.vertices) == tree_mesh.n_total_nodes  # hanging nodes included
    assert np.array_equal(_rows(m.vertices), _rows(tree_mesh.total_nodes))
    assert set(map(tuple, _rows(tree_mesh.nodes))) <= set(map(tuple, _rows(m.vertices)))  # gridN among them
    assert m.report.leaves == tree_mesh.n_cells and m.report.volume_ok and m.report.nonconforming_faces == 0
    # the leaf numbers are discretize's cell indices: each element lies in its cell
    low, high = tree_mesh.cell_bounds[:, 0::2], tree_mesh.cell_bounds[:, 1::2]
    for e in range(0, len(m.elements), 5):
        points, cell = m.vertices[m.elements.nodes(e)], m.elements.leaf[e]
        assert np.all(points >= low[cell] - 1e-9) and np.all(points <= high[cell] + 1e-9)


def test_what_it_cannot_mesh_is_one_error():
    faces_only = discretize.TreeMesh([[(1 / 16, 16)]] * 3, diagonal_balance=False)
    faces_only.refine_points([[0.3, 0.6, 0.7]], level=4, padding_cells_by_level=[0, 0, 0, 0])
    with pytest.raises(InputError, match="not 1-irregular .*: build the TreeMesh with diagonal_balance=True"):
        cospherical.from_treemesh(faces_only)
    with pytest.raises(InputError, match="not finalized"):
        cospherical.from_treemesh(discretize.TreeMesh([[(1, 4)]] * 3, diagonal_balance=True))
    oblong = discretize.TreeMesh([[(1, 4)], [(1, 8)], [(1, 4)]], diagonal_balance=True)
    oblong.finalize()
    with pytest.raises(InputError, match="split alike"):
        cospherical.from_treemesh(oblong)
    with pytest.raises(InputError, match="a discretize.TreeMesh"):
        cospherical.from_treemesh(object())
    with pytest.raises(InputError, match="domain= is the TreeMesh's own"):
        cospherical.from_treemesh(discretize.TreeMesh([[(1, 4)]] * 3, diagonal_balance=True), domain=(1, 1, 1))
    with pytest.raises(InputError, match="device= is the TreeMesh's own"):  # it said "not domain=", not given
        cospherical.from_treemesh(discretize.TreeMesh([[(1, 4)]] * 3, diagonal_balance=True), device="d.yaml")
    nan_origin = discretize.TreeMesh([[(1 / 4, 4)]] * 3, diagonal_balance=True, origin=[float("nan"), 0, 0])
    nan_origin.refine_points([[0.3, 0.6, 0.7]], level=2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy's "invalid value encountered in cast" was printed, then a leaf -2**63
        with pytest.raises(InputError, match="must be finite numbers"):
            cospherical.from_treemesh(nan_origin)
