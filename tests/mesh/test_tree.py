"""The octree as arrays: cell keys and positions, children, neighbourhoods, leaves from split cells, the leaf bound."""

from __future__ import annotations

from fractions import Fraction
from itertools import product

import numpy as np
import pytest

from cospherical.errors import InputError
from cospherical.mesh.tree import (cells_of, check_leaf_count, children, distinct, keys_of, leaves_from_splits,
                                   neighbour_offsets, neighbours)


def test_keys_and_positions_are_inverse_and_children_lie_in_their_parent():
    level = 3
    cells = np.array(list(product(range(8), repeat=3)), dtype=np.int64)
    keys = keys_of(level, cells)
    assert sorted(keys.tolist()) == list(range(8 ** 3))  # one key per cell, dense
    assert cells_of(level, keys).tolist() == cells.tolist()
    kids = children(level, keys[:5])
    assert len(kids) == 40 and np.all(np.diff(kids) > 0)
    assert sorted(keys_of(level, cells_of(level + 1, kids) // 2).tolist()) == sorted(np.repeat(keys[:5], 8).tolist())


def test_distinct_is_numpys_unique_and_keeps_the_dtype():
    keys = np.random.default_rng(7).integers(0, 50, size=400).astype(np.int32)
    found = distinct(keys)
    assert found.dtype == np.int32 and found.tolist() == np.unique(keys).tolist()
    assert distinct(np.zeros(0, dtype=np.int64)).tolist() == []


@pytest.mark.parametrize("balance, most", [("edge", 2), ("vertex", 3)])
def test_neighbours_are_the_cells_within_one_step_inside_the_domain(balance, most):
    level, cell = 2, (0, 1, 3)
    found = neighbours(level, np.array([cell], dtype=np.int64), neighbour_offsets(balance))
    expected = sorted(keys_of(level, np.array([c], dtype=np.int64))[0]
                      for c in product(range(4), repeat=3)
                      if sum(abs(a - b) for a, b in zip(c, cell)) <= most and max(abs(a - b) for a, b in zip(c, cell)) <= 1)
    assert found.tolist() == expected


def test_leaves_of_split_cells_tile_the_domain_once():
    # the root split, and at level 1 the cells 0 and 7 split: 6 + 16 leaves
    split = [np.zeros(1, dtype=np.int64), np.array([0, 7], dtype=np.int64)]
    levels, positions = leaves_from_splits(split)
    assert len(levels) == 22 and sorted(set(levels.tolist())) == [1, 2]
    assert sum(Fraction(1, 8 ** int(level)) for level in levels) == 1
    finest = {tuple(int(x) for x in (p << (2 - level)) + d) for level, p in zip(levels.tolist(), positions)
              for d in product(range(1 << (2 - level)), repeat=3)}
    assert len(finest) == 64  # every level-2 cell covered, by exactly one leaf (22 leaves, 64 cells, no repeat)


def test_a_leaf_count_above_the_bound_is_refused_naming_both():
    check_leaf_count(10, "the tree has", max_leaves=10)
    with pytest.raises(InputError, match="the tree has 11 leaves, above the bound of 10"):
        check_leaf_count(11, "the tree has", max_leaves=10)
