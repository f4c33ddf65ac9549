"""A 1-irregular octree over a box domain: refined by shapes and balanced, or brought as a list of leaves.

Every decision (does a cell meet a shape, do the leaves tile the domain, is the tree
balanced) is made with integers.  A tree is 2:1 balanced exactly when every neighbour
(same level) of a split cell exists, i.e. its parent is split; that closure, taken
from the finest level down, is the coarsest balanced tree containing the refinement
(:func:`build_octree`).  The pieces, each in its module, are gathered here, where the
mesher and its users import them: the tree as arrays (:mod:`cospherical.mesh.tree`), the
shapes and the cells they meet (:mod:`cospherical.mesh.refinement`), a tree brought as a
list of leaves (:mod:`cospherical.mesh.leaf_list`).
"""

from __future__ import annotations

import warnings
from typing import Any, Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from ..choices import BALANCES
from ..core.configuration import Box
from ..errors import CosphericalWarning, InputError, shown
from .leaf_list import leaf_list_order, leaves_octree
from .refinement import Shape, estimate_leaves, meets_shape, parse_shape
from .tree import (BYTES_PER_LEAF, MAX_LEVEL, Octree, cells_of, check_leaf_count, children, distinct, leaf_bound,
                   leaves_from_splits, neighbour_offsets, neighbours, parents)

__all__ = ["BYTES_PER_LEAF", "MAX_LEVEL", "Octree", "Shape", "build_octree", "check_leaf_count", "distinct",
           "estimate_leaves", "leaf_bound", "leaf_list_order", "leaves_octree", "parse_shape"]


def build_octree(box: Box, levels: int, shapes: Sequence[Shape], balance: str = "vertex",
                 max_leaves: int | None = None,
                 must_split: Callable[[int, NDArray[np.int64]], NDArray[np.bool_]] | None = None, resolve: int = 0,
                 name: str | None = None) -> Octree:
    """Refine every cell whose closed box meets a shape down to ``levels``, then 2:1 balance (coarsest).

    ``balance``: ``vertex`` (leaves touching across a face, an edge or a corner
    differ by at most one level; the default) or ``edge`` (faces and edges only).
    Face-only balance is refused: it is not 1-irregular (an edge can get two points).
    A tree whose estimated leaves (:func:`estimate_leaves`) exceed ``max_leaves``
    (default :func:`leaf_bound`) is refused before any cell is visited.
    ``must_split(level, cells)`` (cells n x 3 at ``level``): which cells are split
    whatever the shapes say, at every level below ``max(levels, resolve)`` (a device's
    region boundaries, :mod:`cospherical.mesh.device`).  A shape that does not meet the
    closed domain refines nothing: it is run without it, with a
    :class:`~cospherical.errors.CosphericalWarning` naming it (most likely a typo in a
    coordinate, or a shape meant for a domain of other lengths).

    Examples
    --------
    >>> tree = build_octree(Box.parse([1, 1, 1]), 2, [parse_shape("point:0.1,0.1,0.1")])
    >>> len(tree), sorted(set(tree.levels.tolist()))
    (15, [1, 2])
    >>> build_octree(Box.parse([1, 1, 1]), 2, [], balance="face")
    Traceback (most recent call last):
    ...
    cospherical.errors.InputError: --balance face: balance across faces alone is not 1-irregular (an edge can get two Steiner points); use edge or vertex
    """
    if balance == "face":
        raise InputError("--balance face: balance across faces alone is not 1-irregular "
                         "(an edge can get two Steiner points); use edge or vertex")
    known = next((kind for kind in BALANCES if kind == balance), None)
    if known is None:
        raise InputError(f"--balance {shown(balance)}: choose vertex or edge")
    if isinstance(levels, bool) or not isinstance(levels, int) or not 0 <= levels <= MAX_LEVEL:
        raise InputError(f"--levels {shown(levels)}: must be an integer from 0 to {MAX_LEVEL}")
    name = f"--levels {levels}" if name is None else name
    check_leaf_count(estimate_leaves(box, levels, shapes), f"{name}: an estimated", max_leaves)
    split: list[NDArray[np.integer[Any]]] = []
    existing = np.zeros(1, dtype=np.int64)
    deepest = max(levels, resolve)
    for level in range(deepest):
        cells = cells_of(level, existing)
        hit = np.zeros(len(cells), dtype=bool)
        for shape in shapes if level < levels else ():
            meets = meets_shape(shape, box, level, cells)
            if level == 0 and not meets.any():  # the root cell is the whole closed domain
                warnings.warn(f"refine shape {shown(shape.text)} does not meet the domain: it refines nothing",
                              CosphericalWarning, stacklevel=2)
            hit |= meets
        if must_split is not None:
            hit |= must_split(level, cells)
        split.append(existing[hit])
        # every cell of the next level is or holds a leaf: the estimate's guard, before the children exist
        check_leaf_count(8 * len(split[-1]), f"{name}: level {level + 1} has at least", max_leaves)
        existing = children(level, split[-1])
    offsets = neighbour_offsets(known)
    for level in range(deepest - 1, 0, -1):
        # every neighbour of a split cell must exist: its parent must be split
        need = neighbours(level, cells_of(level, split[level]), offsets)
        split[level - 1] = distinct(np.concatenate([split[level - 1], parents(level, need)]), runs=True)
    levels_, positions = leaves_from_splits(split)
    check_leaf_count(len(levels_), f"{name}: balanced, the tree has", max_leaves)
    return Octree(box, levels_, positions, vertex_balanced=balance == "vertex")
