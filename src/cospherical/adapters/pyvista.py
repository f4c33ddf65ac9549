"""A mesh as a pyvista (VTK) unstructured grid in memory: polyhedra included, the VTU file's data kept.

pyvista (``pip install cospherical[pyvista]``) is imported when called.  The grid is
the one ``mesh.vtu`` holds (:func:`cospherical.formats.mesh.vtu_grid`): standard VTK
cells where an element is one, ``VTK_POLYHEDRON`` with its faces for the others,
cells sorted by VTK cell type, cell data ``element`` (the element each cell is),
``type``, ``leaf``, ``fvm`` and point data ``grid_coordinates``; the field data's text
(type ids and names, the domain) as strings rather than UTF-8 bytes.
"""

from __future__ import annotations

import importlib
from collections.abc import Sequence
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError
from ..formats.mesh import vtu_grid
from ..formats.vtu import VTK_CELL

if TYPE_CHECKING:
    import pyvista

    from ..mesh.assembly import Mesh

__all__ = ["import_pyvista", "legacy_cells", "to_pyvista"]


def import_pyvista() -> ModuleType:
    """The pyvista module, or one clear error when it is missing."""
    try:
        pyvista = importlib.import_module("pyvista")  # a module to the checker, which does not follow pyvista
    except ImportError as error:
        raise InputError(f"pyvista is not installed ({error.name or error}): pip install 'cospherical[pyvista]'") \
            from None
    return pyvista


def legacy_cells(types: np.ndarray, connectivity: np.ndarray, offsets: np.ndarray, faces: np.ndarray | None,
                 faceoffsets: np.ndarray | None) -> np.ndarray:
    """VTK's legacy cell array (per cell its size, then its ids; a polyhedron's ids are its face stream).

    From VTK's layout (``offsets``: where each cell ends in ``connectivity``; a
    polyhedron's face stream ends at ``faceoffsets`` in ``faces``), built by array
    indexing, never per cell.
    """
    ends = np.asarray(offsets, dtype=np.int64)
    starts = np.r_[0, ends[:-1]]
    source = np.asarray(connectivity, dtype=np.int64)
    polyhedral = types == VTK_CELL["polyhedron"]
    if faces is not None and polyhedral.any():
        stream_ends = np.asarray(faceoffsets, dtype=np.int64)[polyhedral]
        stream_starts = np.r_[0, stream_ends[:-1]]
        starts = starts.copy()
        ends = ends.copy()
        starts[polyhedral] = len(source) + stream_starts  # the streams follow the connectivity in ``source``
        ends[polyhedral] = len(source) + stream_ends
        source = np.concatenate([source, np.asarray(faces, dtype=np.int64)])
    sizes = ends - starts
    heads = np.r_[0, np.cumsum(sizes + 1)[:-1]]  # where each cell's size goes
    cells = np.empty(int((sizes + 1).sum()), dtype=np.int64)
    cells[heads] = sizes
    body = np.ones(len(cells), dtype=bool)
    body[heads] = False
    cells[body] = source[np.repeat(starts, sizes) + (np.arange(int(sizes.sum())) - np.repeat(np.cumsum(sizes) - sizes,
                                                                                               sizes))]
    return cells


def to_pyvista(mesh: Mesh, point_data: dict[str, np.ndarray] | None = None, cell_data: dict[str, np.ndarray] | None = None,
               leaves: np.ndarray | None = None, origin: Sequence[float] = (0.0, 0.0, 0.0),
               field_data: dict[str, np.ndarray] | None = None) -> pyvista.UnstructuredGrid:
    """``mesh`` (an assembled :class:`~cospherical.mesh.assembly.Mesh`) as a ``pyvista.UnstructuredGrid``.

    ``point_data``, ``cell_data`` (rows in vertex and element order), ``leaves`` and
    ``field_data`` as :func:`~cospherical.formats.mesh.write_vtu` takes them; ``origin``
    moves the points (the mesh's own coordinates start at 0).
    """
    pyvista = import_pyvista()
    grid = vtu_grid(mesh, point_data, cell_data, leaves, field_data)
    cells = legacy_cells(grid.types, grid.connectivity, grid.offsets, grid.faces, grid.faceoffsets)
    result = pyvista.UnstructuredGrid(cells, grid.types, grid.points + np.asarray(origin, dtype=np.float64))
    for name, values in grid.point_data.items():
        result.point_data[name] = np.asarray(values)
    for name, values in grid.cell_data.items():
        result.cell_data[name] = np.asarray(values)
    for name, values in grid.field_data.items():
        if values.dtype == np.uint8:  # text: one string per line
            result.field_data[name] = np.array(bytes(values).decode().split("\n"))
        else:
            result.field_data[name] = values
    return result
