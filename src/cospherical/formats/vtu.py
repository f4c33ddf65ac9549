"""Mesh export: a tessellation as a VTU file (meshio) that opens in ParaView.

Standard elements are written as VTK tetra, pyramid, wedge and hexahedron cells.
VTU cannot mix polyhedral cells with other kinds, so when any element has no
VTK cell type every element is written as a VTK_POLYHEDRON with its faces.
Cell data: ``type_hash`` (the 6 hex digits of the element type id, as an
integer) and ``vertices``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..core.tessellation import Tessellation
from ..errors import InputError
from ..files.yamlio import atomic_path

__all__ = ["to_meshio", "write_meshio", "write_vtu"]


def to_meshio(tess: Tessellation):
    import meshio

    real = tess.configuration.real_nodes()
    ids = sorted(real)
    index = {node: i for i, node in enumerate(ids)}
    points = np.array([real[i] for i in ids], dtype=float)
    standard = all(e.type.vtk for e in tess.elements)
    cells, type_hash, vertices = [], [], []
    for element in tess.elements:
        if standard:
            cells.append(meshio.CellBlock(element.type.vtk, np.array([[index[n] for n in element.nodes]])))
        else:
            faces = [np.array([index[n] for n in face]) for face in element.polyhedron.faces]
            cells.append(meshio.CellBlock(f"polyhedron{len(element.nodes)}", [faces]))
        type_hash.append(np.array([int(element.type.id.rsplit("-", 1)[1], 16)]))
        vertices.append(np.array([len(element.nodes)]))
    return meshio.Mesh(points, cells, cell_data={"type_hash": type_hash, "vertices": vertices})


def write_vtu(tess: Tessellation, path: str | Path) -> None:
    """Write the tessellation to ``path`` atomically (see :func:`write_meshio`)."""
    write_meshio(to_meshio(tess), path)


def write_meshio(converted, path: str | Path) -> None:
    """Write a :class:`meshio.Mesh` as VTU atomically (see :func:`~cospherical.files.yamlio.atomic_path`):
    meshio wants a file name, so a temporary one, then rename."""
    import meshio

    with atomic_path(path) as tmp:
        try:
            meshio.write(tmp, converted, file_format="vtu")
        except OSError as error:
            raise InputError(f"{path}: cannot write: {error.strerror or error}") from None
