"""A mesh as a ``meshio.Mesh`` of tetrahedra: meshio's cell blocks hold standard cells, not mixed polyhedra.

Every element is split into tetrahedra without new vertices, conforming, each face
split the same way from both sides (:func:`cospherical.mesh.tetrahedra.split_tetrahedra`:
the split keeps the exact dual, its added edges couple 0).  meshio is imported when called.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError
from ..mesh.tetrahedra import split_tetrahedra

if TYPE_CHECKING:
    import meshio

    from ..mesh.assembly import Mesh

__all__ = ["to_meshio"]


def to_meshio(mesh: Mesh, points: np.ndarray, leaves: np.ndarray | None = None) -> meshio.Mesh:
    """``mesh`` (an assembled :class:`~cospherical.mesh.assembly.Mesh`) split into tetrahedra, as a ``meshio.Mesh``.

    ``points``: the vertices' coordinates.  Cell data of the one ``tetra`` block:
    ``element`` (the element each tetrahedron comes from), ``type`` (the element's
    type, an index into the sorted type ids of :meth:`~cospherical.mesh.assembly.Mesh.element_types`),
    ``leaf`` (its leaf, numbered by ``leaves`` when given), ``region``.
    """
    try:
        import meshio
    except ImportError as error:
        raise InputError(f"meshio is not installed ({error.name or error}): pip install 'cospherical[meshio]'") \
            from None
    tets = split_tetrahedra(mesh)
    _, element_type = mesh.element_types()
    leaf = mesh.element_leaf if leaves is None else np.asarray(leaves)[mesh.element_leaf]
    parent = tets.parent
    cell_data = {"element": [parent.astype(np.int64)], "type": [element_type[parent].astype(np.int32)],
                 "leaf": [leaf[parent].astype(np.int64)], "region": [tets.region.astype(np.int32)]}
    return meshio.Mesh(np.asarray(points, dtype=np.float64), [("tetra", tets.nodes.astype(np.int64))],
                       cell_data=cell_data)
