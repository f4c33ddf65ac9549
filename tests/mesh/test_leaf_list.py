"""A tree brought as a list of leaves: values that are not plain integers refused naming the leaf, any
integer type accepted."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from cospherical.core.configuration import Box
from cospherical.errors import InputError
from cospherical.mesh.leaf_list import leaves_octree

P8 = [[i, j, k] for k in (0, 1) for j in (0, 1) for i in (0, 1)]
UNIT = Box.parse([1, 1, 1])


@pytest.mark.parametrize("levels, positions, needle", [
    ([0.9], [[0, 0, 0]], "leaf 0: level 0.9 is not an integer (a float)"),  # was level 0
    ([1] * 5 + [1.5, 1, 1], P8, "leaf 5: level 1.5 is not an integer"),
    (np.full(8, 1.0), P8, "leaf 0: level 1.0 is not an integer (a float)"),  # whole, but a float: never truncated
    ([1] * 8, P8[:7] + [[1, 1, 0.5 + 1]], "leaf 7: position 1.5 is not an integer"),  # was position 1
    ([1] * 8, P8[:7] + [[1, 1, np.float32(1)]], "leaf 7: position 1.0 is not an integer (a float)"),
    ([1] * 8, np.array(P8, dtype=float), "leaf 0: position 0.0 is not an integer"),
    ([True] * 8, P8, "leaf 0: level True is not an integer (a bool)"),
    (np.ones(8, dtype=bool), P8, "leaf 0: level True is not an integer (a bool)"),
    ([1] * 8, P8[:7] + [[1, 1, 2 ** 70]], "leaf 7: position 1180591620717411303424 is too large"),  # OverflowError
    ([1] * 8, P8[:7] + [[1, 1, 2 ** 63]], "leaf 7: position 9223372036854775808 is too large"),
    ([-(2 ** 80)], [[0, 0, 0]], "leaf 0: level -1208925819614629174706176 is too large"),
    (np.ones(8, dtype=np.uint64), np.array(P8[:7] + [[1, 1, 2 ** 64 - 1]], dtype=np.uint64),
     "leaf 7: position 18446744073709551615 is too large"),  # wrapped to -1 by a cast
    ([1] * 8, P8[:7] + [[1, "1", 1]], "leaf 7: position '1' is not an integer (a str)"),
    ([None], [[0, 0, 0]], "leaf 0: level None is not an integer"),
    ([1] * 8, P8[:7] + [[1, 1]], "leaf 7: position [1, 1] is not 3 integers"),  # ValueError from numpy
    ([Fraction(1, 2)], [[0, 0, 0]], "leaf 0: level Fraction(1, 2) is not an integer"),
])
def test_a_leaf_that_is_not_integers_is_refused_naming_it(levels, positions, needle):
    import cospherical

    with pytest.raises(InputError) as raised:
        leaves_octree(UNIT, levels, positions)
    assert type(raised.value) is InputError and str(raised.value).startswith(f"leaves: {needle}"), raised.value
    if len(levels) == 8 and not isinstance(positions, np.ndarray) and not isinstance(levels, np.ndarray) \
            and levels[0] is not True:  # (rows of ints with a bool are ints to numpy, and to build_mesh)
        rows = [[level, *position] for level, position in zip(levels, positions)]
        with pytest.raises(InputError):  # the API's rows: refused too, never truncated
            cospherical.build_mesh(domain=(1, 1, 1), leaves=rows, uniform=False)


def test_leaves_of_any_integer_type_are_accepted():
    expected = leaves_octree(UNIT, [1] * 8, P8)
    for levels, positions in ((np.ones(8, dtype=np.uint8), np.array(P8, dtype=np.int16)),
                              ([np.int64(1)] * 8, [[np.int32(x) for x in p] for p in P8])):
        tree = leaves_octree(UNIT, levels, positions)
        assert tree.levels.tolist() == expected.levels.tolist() and tree.positions.tolist() == expected.positions.tolist()
