"""An octree from discretize (SimPEG's meshes): a ``discretize.TreeMesh`` as the leaf list the mesher takes.

A TreeMesh cell has a level (0: the whole domain; ``max_level``: its base cells)
and a centre, which give ``(level, i, j, k)``: at level ``L`` the cell covers
``[i, i+1] x [j, j+1] x [k, k+1]`` in units of ``1/2**L`` of the domain.  The domain
must be one root cell split alike along the three axes (``2**max_level`` base cells a
side, each axis of one cell width), and the tree 1-irregular: build it with
``diagonal_balance=True`` (the mesher checks it and names a bad leaf).  discretize is
imported only by its caller: this module reads the object's attributes.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError

if TYPE_CHECKING:
    import discretize

__all__ = ["TreeMeshLeaves", "treemesh_leaves"]


@dataclass(frozen=True)
class TreeMeshLeaves:
    """A TreeMesh's domain and leaves: ``lengths`` (the sides as exact decimal text), ``origin``, ``levels``, ``positions``."""

    lengths: tuple[str, str, str]
    origin: tuple[float, float, float]
    levels: np.ndarray
    positions: np.ndarray


def treemesh_leaves(tree_mesh: discretize.TreeMesh) -> TreeMeshLeaves:
    """The leaves of ``tree_mesh`` (a 3-D ``discretize.TreeMesh``) and its domain.

    The sides are the sums of the base cell widths, written as the shortest decimal
    that reads back as the same float (``repr``), which the mesher takes exactly.
    """
    if not getattr(tree_mesh, "finalized", True):
        raise InputError("from_treemesh: the TreeMesh is not finalized: call its finalize() (refine_points and the "
                         "other refine methods do by default)")
    try:
        widths = [np.asarray(h, dtype=np.float64) for h in tree_mesh.h]
        shape = tuple(int(n) for n in tree_mesh.shape_cells)
        origin = tuple(float(x) for x in tree_mesh.origin)
        levels = np.asarray(tree_mesh.cell_levels_by_index(np.arange(tree_mesh.n_cells)), dtype=np.int64)
        centers = np.asarray(tree_mesh.cell_centers, dtype=np.float64)
    except AttributeError as error:
        raise InputError(f"from_treemesh: a discretize.TreeMesh, not {type(tree_mesh).__name__} ({error})") from None
    if len(widths) != 3:
        raise InputError(f"from_treemesh: a 3-D TreeMesh, not {len(widths)}-D")
    if not all(np.isfinite(x) for x in origin) or not all(np.isfinite(h).all() and (h > 0).all() for h in widths):
        # a NaN origin gave every leaf the position -2**63 (numpy's cast of NaN), named as "outside the domain"
        raise InputError(f"from_treemesh: its origin {origin} and cell widths must be finite numbers, the widths > 0")
    if len(set(shape)) != 1:
        raise InputError(f"from_treemesh: {' x '.join(map(str, shape))} base cells: the root cell must be split "
                         "alike along the three axes (the same power of two a side)")
    if any(not np.all(h == h[0]) for h in widths):
        raise InputError("from_treemesh: base cells of different widths along an axis: the leaves are the domain "
                         "scaled by powers of two")
    lengths = tuple(repr(float(h.sum())) for h in widths)
    scale = (1 << levels)[:, None] / np.array([float(length) for length in lengths])
    positions = np.floor((centers - np.array(origin)) * scale).astype(np.int64)
    return TreeMeshLeaves((lengths[0], lengths[1], lengths[2]), (origin[0], origin[1], origin[2]), levels, positions)
