"""``OctreeMesh.to_meshio``: the tetrahedral split as a meshio.Mesh that meshio writes and reads back."""

from __future__ import annotations

import sys

import meshio
import numpy as np
import pytest

import cospherical
from cospherical.errors import InputError

pytestmark = pytest.mark.oracle_meshio


def _volumes(points: np.ndarray, tets: np.ndarray) -> np.ndarray:
    p = points[tets]
    return np.einsum("ij,ij->i", p[:, 1] - p[:, 0], np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0])) / 6


def test_tetrahedra_fill_each_element_and_survive_a_vtu_round_trip(tmp_path):
    m = cospherical.build_mesh(domain=(1, 2, 4), levels=3, refine=["sphere:0.5,1,2,0.6"], uniform=False)
    mm = m.to_meshio()
    tets = mm.cells_dict["tetra"]
    volume = _volumes(mm.points, tets)
    assert volume.min() > 0 and volume.sum() == pytest.approx(8.0, rel=1e-12)
    element = mm.cell_data["element"][0]
    assert set(element.tolist()) == set(range(len(m.elements)))  # every element split, none dropped
    # each tetrahedron's vertices are vertices of its parent element
    for t in range(0, len(tets), 7):
        assert set(tets[t].tolist()) <= set(m.elements.nodes(element[t]).tolist())
    meshio.write(tmp_path / "tets.vtu", mm)
    back = meshio.read(tmp_path / "tets.vtu")
    assert np.array_equal(back.cells_dict["tetra"], tets) and np.allclose(back.points, mm.points)


def test_without_meshio_one_clear_error(monkeypatch):
    m = cospherical.build_mesh(domain=(1, 1, 1), levels=0, refine=["point:0,0,0"], uniform=False)
    monkeypatch.setitem(sys.modules, "meshio", None)
    with pytest.raises(InputError, match=r"pip install 'cospherical\[meshio\]'"):
        m.to_meshio()
