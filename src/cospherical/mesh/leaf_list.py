"""A tree brought as a list of leaves (level, i, j, k): read as integers, checked to be an octree, ordered.

The list is the user's (a leaf file, the API's rows, a ``discretize.TreeMesh``): every
value is checked to be a plain integer, the leaves to tile the domain (no overlap, no
gap) and to be 1-irregular, and each refusal names the leaf by its index in the list.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np
from numpy.typing import NDArray

from ..core.configuration import Box
from ..errors import InputError, shown
from .tree import MAX_LEVEL, Octree, cells_of, children, distinct, keys_of, leaves_from_splits, neighbour_offsets, \
    neighbours

__all__ = ["leaf_list_order", "leaves_octree"]


def _leaf_integers(values: object, width: int, where: str, what: str) -> NDArray[np.int64]:
    """Levels (``width`` 1) or positions (rows of 3) as a flat int64 array, each an integer.

    numpy's own conversion to int64 truncates (a level 0.9 becomes 0, a position i + 0.5
    becomes i), reads a bool array as 0 and 1 and raises OverflowError past 64 bits: what
    numpy does not read as integers is looked at value by value, and the first that is not
    a plain integer of at most 64 bits raises InputError naming its leaf.
    """
    int64 = np.iinfo(np.int64)
    try:
        array = values if isinstance(values, np.ndarray) else np.asarray(values)
    except (ValueError, OverflowError, TypeError):  # rows of different lengths, ints past 64 bits
        array = None
    if array is not None and array.dtype.kind in "iu":
        flat = array.reshape(-1)
        if array.dtype.kind == "u" and array.dtype.itemsize == 8 and len(flat) and flat.max() > int64.max:
            bad = int(np.flatnonzero(flat > int64.max)[0])
            raise InputError(f"{where}: leaf {bad // width}: {what} {flat[bad]} is too large")
        flat = flat.astype(np.int64)
    else:
        try:
            flat = np.asarray(values, dtype=object).reshape(-1)
        except ValueError:
            raise InputError(f"{where}: the {what}s are not a list of integers") from None
        if width > 1 and flat.ndim == 1 and any(isinstance(value, (list, tuple, np.ndarray)) for value in flat):
            n = next(n for n, row in enumerate(flat) if not isinstance(row, (list, tuple, np.ndarray))
                     or len(row) != width)  # rows of different lengths: the first that is not 3 long
            raise InputError(f"{where}: leaf {n}: {what} {shown(flat[n])} is not {width} integers")
        for n, value in enumerate(flat):
            if not isinstance(value, (int, np.integer)) or isinstance(value, (bool, np.bool_)):
                value = value.item() if isinstance(value, np.generic) else value
                raise InputError(f"{where}: leaf {n // width}: {what} {shown(value)} is not an integer "
                                 f"(a {type(value).__name__})")
            if not int64.min <= value <= int64.max:
                raise InputError(f"{where}: leaf {n // width}: {what} {shown(int(value))} is too large")
        flat = flat.astype(np.int64)
    if len(flat) % width:
        raise InputError(f"{where}: {len(flat)} position numbers: not rows of 3")
    return flat


def leaves_octree(box: Box, levels: Sequence[int] | NDArray[np.integer[Any]], positions: Sequence[Sequence[int]] | NDArray[np.integer[Any]],
                  where: str = "leaves") -> Octree:
    """Check a list of leaves (level, i, j, k) and order it as an :class:`Octree`.

    The leaves must tile the domain (no overlap, no gap) and be 1-irregular (leaves
    touching across a face or an edge differ by at most one level); otherwise
    :class:`~cospherical.errors.InputError` names a bad leaf by its index in the list.

    Examples
    --------
    >>> tree = leaves_octree(Box.parse([1, 1, 1]), [0], [[0, 0, 0]])
    >>> len(tree), tree.depth
    (1, 0)
    >>> leaves_octree(Box.parse([1, 1, 1]), [1] * 7, [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0],
    ...                                               [0, 0, 1], [1, 0, 1], [0, 1, 1]])
    Traceback (most recent call last):
    ...
    cospherical.errors.InputError: leaves: no leaf covers the cell at level 1, position 1 1 1
    """
    levels = _leaf_integers(levels, 1, where, "level")
    positions = _leaf_integers(positions, 3, where, "position").reshape(-1, 3)
    if len(levels) == 0:
        raise InputError(f"{where}: no leaves")
    if len(levels) != len(positions):
        raise InputError(f"{where}: {len(levels)} levels but {len(positions)} positions")
    bad = np.flatnonzero((levels < 0) | (levels > MAX_LEVEL))
    if len(bad):
        raise InputError(f"{where}: leaf {bad[0]}: level {levels[bad[0]]} is not in 0..{MAX_LEVEL}")
    bad = np.flatnonzero(np.any((positions < 0) | (positions >= (1 << levels)[:, None]), axis=1))
    if len(bad):
        i = bad[0]
        raise InputError(f"{where}: leaf {i}: position {' '.join(map(str, positions[i]))} is outside the domain "
                         f"at level {levels[i]} (0..{(1 << levels[i]) - 1})")
    depth = int(levels.max())
    keys = {level: keys_of(level, positions[levels == level]) for level in range(depth + 1)}
    index = {level: np.flatnonzero(levels == level) for level in range(depth + 1)}
    for level in range(depth + 1):
        order = np.argsort(keys[level], kind="stable")
        k = keys[level][order]
        same = np.flatnonzero(k[1:] == k[:-1])
        if len(same):
            a, b = sorted(index[level][order[same[0]:same[0] + 2]])
            raise InputError(f"{where}: leaf {b} repeats leaf {a} (level {level}, position "
                             f"{' '.join(map(str, positions[a]))})")
    # split[l]: the cells of level l that are ancestors of a leaf; a leaf must not be one
    split = []
    for level in range(depth):
        deeper = [keys_of(level, cells_of(d, keys[d]) >> (d - level)) for d in range(level + 1, depth + 1)]
        split.append(distinct(np.concatenate(deeper)) if deeper else np.zeros(0, dtype=np.int64))
        clash = np.isin(keys[level], split[level])
        if clash.any():
            i = index[level][np.flatnonzero(clash)[0]]
            raise InputError(f"{where}: leaf {i} (level {level}, position {' '.join(map(str, positions[i]))}) "
                             "overlaps smaller leaves inside it")
    # no gap: every child of a split cell exists (is a leaf or split)
    existing = np.zeros(1, dtype=np.int64)
    for level in range(depth + 1):
        here = np.union1d(keys[level], split[level] if level < depth else np.zeros(0, dtype=np.int64))
        missing = existing[~np.isin(existing, here)]
        if len(missing):
            cell = cells_of(level, missing[:1])[0]
            raise InputError(f"{where}: no leaf covers the cell at level {level}, position "
                             f"{' '.join(map(str, cell))}")
        if level < depth:
            existing = children(level, split[level])
    # 1-irregular: every face or edge neighbour of a split cell exists
    offsets = neighbour_offsets("edge")
    for level in range(1, depth):
        need = neighbours(level, cells_of(level, split[level]), offsets)
        parents = keys_of(level - 1, cells_of(level, need) // 2)
        lacking = np.flatnonzero(~np.isin(parents, split[level - 1]))
        if len(lacking):
            cell = cells_of(level, need[lacking[:1]])[0]
            # the leaf holding that cell is coarser than its parent: find it by its ancestors
            for coarse in range(level - 1, -1, -1):
                key = keys_of(coarse, (cell >> (level - coarse))[None])[0]
                hit = np.flatnonzero(keys[coarse] == key)
                if len(hit):
                    i = index[coarse][hit[0]]
                    raise InputError(f"{where}: leaf {i} (level {coarse}, position "
                                     f"{' '.join(map(str, positions[i]))}) touches leaves of level {level + 1} "
                                     "across a face or an edge: not 1-irregular (2:1 balance)")
    levels_, positions_ = leaves_from_splits(split)
    return Octree(box, levels_, positions_)


def leaf_list_order(levels: Sequence[int] | NDArray[np.integer[Any]],
                    positions: Sequence[Sequence[int]] | NDArray[np.integer[Any]]) -> NDArray[np.intp]:
    """For each leaf of ``leaves_octree(box, levels, positions)``, in the tree's order, its index in the list.

    The tree sorts its leaves by (level, key); a list that :func:`leaves_octree`
    accepted holds each leaf once, so sorting the list the same way pairs them.

    Examples
    --------
    >>> levels, positions = [1] * 8, [[i >> 2, (i >> 1) & 1, i & 1] for i in range(8)][::-1]
    >>> tree = leaves_octree(Box.parse([1, 1, 1]), levels, positions)
    >>> order = leaf_list_order(levels, positions)
    >>> order.tolist(), [positions[i] for i in order] == tree.positions.tolist()
    ([7, 6, 5, 4, 3, 2, 1, 0], True)
    """
    levels = np.asarray(levels, dtype=np.int64).reshape(-1)
    positions = np.asarray(positions, dtype=np.int64).reshape(-1, 3)
    keys = np.zeros(len(levels), dtype=np.int64)
    for level in np.unique(levels).tolist():
        at = levels == level
        keys[at] = keys_of(level, positions[at])
    return np.lexsort((keys, levels))
