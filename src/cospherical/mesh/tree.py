"""An octree held as arrays: cells as linear keys level by level, the leaves, and how many a machine holds.

A cell at level ``l`` is the integer position ``(i, j, k)`` with ``0 <= i, j, k < 2**l``;
its box in unit coordinates of the domain is ``[i/2**l, (i+1)/2**l] x ...``, the real
box that times the domain lengths (A, B, C).  The tree is held as arrays, level by
level, never as Python objects per cell: a cell of level ``l`` is its linear key
``(i * 2**l + j) * 2**l + k``, and a tree is the sorted keys of its split cells per level
(:func:`leaves_from_splits`), or its leaves (:class:`Octree`).  Refinement and balance
(:mod:`cospherical.mesh.octree`) and the check of a leaf list
(:mod:`cospherical.mesh.leaf_list`) both work on these keys.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import product
from typing import Any, Sequence, TypeVar

import numpy as np
from numpy.typing import NDArray

from ..choices import Balance
from ..core.configuration import Box
from ..errors import InputError
from ..files.yamlio import machine_memory

__all__ = ["BYTES_PER_LEAF", "MAX_LEVEL", "Octree", "cells_of", "check_leaf_count", "children", "distinct", "keys_of",
           "leaf_bound", "leaves_from_splits", "neighbour_offsets", "neighbours", "parents"]

MAX_LEVEL = 16  # keys (2**16)**3 and the half-spacing grid (2**17 + 1)**3 stay inside int64
# Peak memory of `cospherical mesh` with every check, per leaf: 1.5 kB measured at 131,258
# leaves (plane:1,1,1,1.5, levels 7); rounded up.
BYTES_PER_LEAF = 2048
_Key = TypeVar("_Key", bound=np.integer[Any])  # an integer array keeps its dtype through distinct


def distinct(keys: NDArray[_Key], runs: bool = False) -> NDArray[_Key]:
    """The distinct values of an integer array, increasing.

    Sort and keep firsts: numpy's hash-based ``unique`` is much slower on int64 keys
    (4 million keys spread over 10**12: 5.5 s against 0.03 s CPU, numpy 2.4).  ``runs``:
    the keys (read in C order) are a few increasing runs, which a stable sort (timsort)
    merges instead of sorting afresh: the corners of 335,504 leaves laid out corner by
    corner, 2.7 million keys in 64 runs, 0.02 s CPU against 0.16 s for numpy's default sort.
    """
    keys = np.sort(keys, axis=None, kind="stable" if runs else None)
    return keys[np.r_[True, keys[1:] != keys[:-1]]] if len(keys) else keys


def keys_of(level: int, cells: NDArray[np.integer[Any]]) -> NDArray[np.int64]:
    """Linear keys of positions (n x 3) at ``level``."""
    n = np.int64(1 << level)
    at = cells.astype(np.int64)
    keys: NDArray[np.int64] = (at[:, 0] * n + at[:, 1]) * n + at[:, 2]
    return keys


def cells_of(level: int, keys: NDArray[np.integer[Any]]) -> NDArray[np.int64]:
    """Positions (n x 3) of linear keys at ``level``."""
    n = np.int64(1 << level)
    keys = keys.astype(np.int64)
    return np.stack([keys // (n * n), (keys // n) % n, keys % n], axis=1)


def neighbour_offsets(balance: Balance) -> NDArray[np.int64]:
    """Neighbour offsets touching a cell across a face and an edge (``edge``), or also a corner (``vertex``)."""
    most = 3 if balance == "vertex" else 2
    return np.array([d for d in product((-1, 0, 1), repeat=3) if sum(map(abs, d)) <= most], dtype=np.int64)


def neighbours(level: int, cells: NDArray[np.integer[Any]], offsets: NDArray[np.int64]) -> NDArray[np.integer[Any]]:
    """Keys of the cells (with the cells themselves) at ``offsets`` (steps of -1, 0, 1 per axis:
    :func:`neighbour_offsets`), inside the domain, distinct and increasing.

    Cells given in key order make one increasing run per offset, merged by a stable sort.
    """
    n = 1 << level
    cells = cells.astype(np.int64)
    base = keys_of(level, cells)
    # per axis, the cells with room below (offset -1) and above (+1) inside the domain
    room = {(axis, step): cells[:, axis] > 0 if step < 0 else cells[:, axis] < n - 1
            for axis in range(3) for step in (-1, 1)}
    near = []
    for offset in offsets.tolist():
        inside = None
        for axis, step in enumerate(offset):
            if step:
                inside = room[axis, step] if inside is None else inside & room[axis, step]
        shift = (offset[0] * n + offset[1]) * n + offset[2]
        near.append((base if inside is None else base[inside]) + shift)
    return distinct(np.concatenate(near) if near else base[:0], runs=True)


def children(level: int, keys: NDArray[np.integer[Any]]) -> NDArray[np.int64]:
    """Keys at ``level + 1`` of the eight children of cells at ``level``."""
    cells = cells_of(level, keys) * 2
    kids = (np.array(list(product((0, 1), repeat=3)))[:, None, :] + cells[None]).reshape(-1, 3)
    return np.sort(keys_of(level + 1, kids), kind="stable")  # child by child: eight increasing runs when keys increase


def parents(level: int, keys: NDArray[np.integer[Any]]) -> NDArray[np.int64]:
    """Keys at ``level - 1`` of the parents of cells at ``level`` (``keys`` increasing), distinct and increasing.

    Halving keeps the order of the cells alike in each coordinate's parity, so the cells
    grouped by their eight parities (a stable sort of 3-bit numbers) make eight increasing
    runs of parents, merged by a stable sort.
    """
    cells = cells_of(level, keys)
    parity = ((cells[:, 0] & 1) << 2 | (cells[:, 1] & 1) << 1 | cells[:, 2] & 1).astype(np.uint8)
    return distinct(keys_of(level - 1, cells[np.argsort(parity, kind="stable")] // 2), runs=True)


@dataclass(frozen=True)
class Octree:
    """Leaves of a 1-irregular octree: ``levels`` (n,) and integer ``positions`` (n x 3), sorted by (level, key).

    ``depth`` is the finest leaf level.  Leaf ``i`` is the box
    ``positions[i] / 2**levels[i]`` (+ one cell) in unit coordinates of the domain.
    ``vertex_balanced``: known by construction to be leaves of a tree over the whole domain
    whose leaves touch across a face, an edge or a corner only when at most one level apart
    (:func:`build_octree` with ``balance="vertex"``): all of them, or a part (a device keeps
    the leaves inside its boxes); the exact Delaunay check then bounds
    where a vertex can lie near a leaf (:mod:`cospherical.mesh.checks.empty_sphere`).  ``False``
    claims nothing.
    """

    box: Box
    levels: NDArray[np.integer[Any]]
    positions: NDArray[np.integer[Any]]
    vertex_balanced: bool = False

    @property
    def depth(self) -> int:
        return int(self.levels.max()) if len(self.levels) else 0

    def __len__(self) -> int:
        return len(self.levels)


def leaves_from_splits(split: Sequence[NDArray[np.integer[Any]]]) -> tuple[NDArray[np.int8], NDArray[np.int64]]:
    """Leaves of the tree whose split cells per level are ``split`` (level 0 is the root)."""
    levels, positions = [], []
    existing = np.zeros(1, dtype=np.int64)  # the root
    for level in range(len(split) + 1):
        here = split[level] if level < len(split) else np.zeros(0, dtype=np.int64)
        leaves = existing[~np.isin(existing, here, assume_unique=True)]
        levels.append(np.full(len(leaves), level, dtype=np.int8))
        positions.append(cells_of(level, leaves))
        if level < len(split):
            existing = children(level, here)
    return np.concatenate(levels), np.concatenate(positions)


def leaf_bound() -> int:
    """The most leaves a mesh may have on this machine: half its memory at :data:`BYTES_PER_LEAF` a leaf."""
    return max(1, machine_memory() // 2 // BYTES_PER_LEAF)


def check_leaf_count(count: int, what: str, max_leaves: int | None = None) -> None:
    """Refuse ``count`` leaves above ``max_leaves`` (default :func:`leaf_bound`), naming both."""
    bound = leaf_bound() if max_leaves is None else max_leaves
    if count > bound:
        raise InputError(f"{what} {count:,} leaves, above the bound of {bound:,} "
                         f"(half this machine's memory at {BYTES_PER_LEAF} bytes a leaf; --max-leaves N sets it)")
