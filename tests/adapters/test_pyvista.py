"""``OctreeMesh.to_pyvista``: the grid in memory is mesh.vtu's, polyhedra included, and its cells fill the domain."""

from __future__ import annotations

import sys

import numpy as np
import pytest

import cospherical
from cospherical.adapters.pyvista import legacy_cells
from cospherical.errors import InputError

pytestmark = pytest.mark.oracle_vtk


@pytest.fixture(scope="module")
def pyvista():
    """pyvista, imported by the tests that use it: held at module level, it is asked by pytest's collection
    for attributes it lacks, and its module ``__getattr__`` then imports pyvista.plotting (~0.5 CPU-s) in
    every worker."""
    import pyvista

    return pyvista


@pytest.fixture(scope="module")
def graded():
    """A 1 x 2 x 4 octree whose global Delaunay cells include general polyhedra (VTK_POLYHEDRON)."""
    return cospherical.build_mesh(domain=(1, 2, 4), levels=4, refine=["sphere:0.5,1,2,0.3"], uniform=False)


def test_cell_volumes_sum_to_the_domain(graded, pyvista):
    grid = graded.to_pyvista()
    assert grid.n_cells == len(graded.elements) and grid.n_points == len(graded.vertices)
    assert pyvista.CellType.POLYHEDRON in set(grid.celltypes.tolist())
    volume = grid.compute_cell_sizes(length=False, area=False)["Volume"]  # VTK's own cell volumes
    assert volume.min() > 0
    assert volume.sum() == pytest.approx(8.0, rel=1e-12)


def test_the_grid_is_the_written_file_as_vtk_reads_it(graded, tmp_path, pyvista):
    graded.write(tmp_path)
    read = pyvista.read(tmp_path / "mesh.vtu")
    grid = graded.to_pyvista()
    assert np.array_equal(read.points, grid.points) and np.array_equal(read.celltypes, grid.celltypes)
    for name in ("element", "type", "leaf", "fvm"):
        assert np.array_equal(read.cell_data[name], grid.cell_data[name]), name
    assert np.array_equal(read.point_data["grid_coordinates"], grid.point_data["grid_coordinates"])
    sizes = [g.compute_cell_sizes(length=False, area=False)["Volume"] for g in (read, grid)]
    assert np.allclose(sizes[0], sizes[1], rtol=0, atol=1e-14)
    assert list(grid.field_data["type_ids"]) == list(graded.elements.type_ids)


def test_a_devices_grid_is_its_written_file_regions_included(tmp_path, pyvista):
    # the regions a solver's materials hang on: in memory as in mesh.vtu (they were only in the file)
    mos = cospherical.build_mesh(device="examples/devices/mos-capacitor.yaml", uniform=False)
    mos.write(tmp_path)
    read, grid = pyvista.read(tmp_path / "mesh.vtu"), mos.to_pyvista()
    assert np.array_equal(read.points, grid.points)
    assert np.array_equal(read.cell_data["region"], grid.cell_data["region"]) and set(grid.cell_data["region"]) == {0, 1}
    for name in ("region_names", "region_materials", "origin"):
        assert [str(x) for x in grid.field_data[name]] == bytes(read.field_data[name]).decode().split("\n"), name
    assert list(grid.field_data["region_names"]) == ["substrate", "oxide"]


def test_the_dual_travels_once_computed():
    m = cospherical.build_mesh(domain=(1, 1, 1), levels=2, refine=["point:0.1,0.1,0.1"], uniform=False)
    assert "control_volume" not in m.to_pyvista().point_data
    m.dual  # computed on first use
    grid = m.to_pyvista()
    assert grid.point_data["control_volume"].sum() == pytest.approx(1.0, rel=1e-12)
    assert grid.cell_data["circumcenter"].shape == (grid.n_cells, 3)


def test_legacy_cells_interleave_sizes_and_face_streams():
    # a tetrahedron, then a polyhedron (a tetrahedron written as faces), then a tetrahedron
    types = np.array([10, 42, 10], dtype=np.uint8)
    connectivity = np.array([0, 1, 2, 3, 4, 5, 6, 7, 0, 2, 4, 6])
    offsets = np.array([4, 8, 12])
    faces = np.array([4, 3, 4, 6, 5, 3, 4, 5, 7, 3, 5, 6, 7, 3, 4, 7, 6])
    cells = legacy_cells(types, connectivity, offsets, faces, np.array([-1, 17, -1]))
    assert cells.tolist() == [4, 0, 1, 2, 3, 17, *faces.tolist(), 4, 0, 2, 4, 6]


def test_without_pyvista_one_clear_error(monkeypatch):
    m = cospherical.build_mesh(domain=(1, 1, 1), levels=0, refine=["point:0,0,0"], uniform=False)
    monkeypatch.setitem(sys.modules, "pyvista", None)  # import pyvista raises ImportError
    with pytest.raises(InputError, match=r"pip install 'cospherical\[pyvista\]'") as raised:
        m.to_pyvista()
    assert "\n" not in str(raised.value)
