"""Octrees refined around shapes: the exact cell tests against a brute force, the size bound, edge and vertex
balance."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from strategies import BOXES, shapes

from cospherical.core.configuration import Box
from cospherical.errors import InputError
from cospherical.mesh import octree
from cospherical.mesh.octree import build_octree, parse_shape

CUBE = Box.parse(["1", "1", "1"])


def test_vertex_balance_is_never_coarser_than_edge_balance():
    shapes = [parse_shape("point:0.3,0.61,0.77")]
    assert len(build_octree(CUBE, 6, shapes, "vertex")) >= len(build_octree(CUBE, 6, shapes, "edge"))


def _brute_meets(shape: octree.Shape, box: Box, level: int, cell) -> bool:
    """Does the closed cell meet the shape: Fractions, one cell at a time (rational lengths only)."""
    n = 1 << level
    lengths = [math.sqrt(float(s)) for s in box.squared]  # sqrt lengths only reach point and box
    v = shape.values
    if shape.kind in ("point", "box"):
        lo, hi = (v[:3], v[:3]) if shape.kind == "point" else (v[:3], v[3:])
        # i * len / n <= hi and (i + 1) * len / n >= lo, squared with signs
        def le(i, q, b):  # i * sqrt(q) <= b, i >= 0
            return b >= 0 and i * i * q <= b * b
        return all(le(cell[a], box.squared[a], hi[a] * n) and not (lo[a] * n > 0 and (cell[a] + 1) ** 2 * box.squared[a]
                   < (lo[a] * n) ** 2) for a in range(3))
    del lengths
    side = [Fraction(math.isqrt(q.numerator), math.isqrt(q.denominator)) for q in box.squared]
    lo = [Fraction(cell[a], n) * side[a] for a in range(3)]
    hi = [Fraction(cell[a] + 1, n) * side[a] for a in range(3)]
    if shape.kind == "plane":
        corners = [sum(v[a] * (hi[a] if bits >> a & 1 else lo[a]) for a in range(3)) for bits in range(8)]
        return min(corners) <= v[3] <= max(corners)
    near = sum(max(lo[a] - v[a], Fraction(0), v[a] - hi[a]) ** 2 for a in range(3))
    far = sum(max(abs(lo[a] - v[a]), abs(hi[a] - v[a])) ** 2 for a in range(3))
    return near <= v[3] ** 2 <= far


@settings(max_examples=80, deadline=None, suppress_health_check=list(HealthCheck))
@given(text=shapes(), texts=BOXES, level=st.integers(0, 3))
def test_cell_tests_match_a_brute_force_and_the_size_bound_holds(text, texts, level):
    box = Box.parse(texts)
    try:
        shape = octree.parse_shape(text)
        n = 1 << level
        cells = np.array([(i, j, k) for i in range(n) for j in range(n) for k in range(n)], dtype=np.int64)
        hits = octree._meets(shape, box, level, cells)
    except Exception as error:  # only the library's own refusal (a sphere over a sqrt length, a bad radius)
        assert type(error).__name__ == "InputError", error
        return
    expected = [_brute_meets(shape, box, level, tuple(cell)) for cell in cells.tolist()]
    assert hits.tolist() == expected
    bound = octree._hits_bound(shape, box, level)
    assert int(hits.sum()) <= bound
    if shape.kind == "box":
        assert int(hits.sum()) == bound
    # the estimate bounds the unbalanced refinement's leaves
    assert octree.estimate_leaves(box, level, [shape]) >= 1 + 7 * sum(
        int(octree._meets(shape, box, m, np.array([(i, j, k) for i in range(1 << m) for j in range(1 << m)
                                                   for k in range(1 << m)], dtype=np.int64)).sum())
        for m in range(level))


def test_a_shape_text_of_any_length_is_named_cut_short():
    # from the API as from --refine: a 220 kB shape text was echoed whole in the error
    for text in ("sphere:" + "1" * 220_000 + ",0,0,1", "x" * 220_000 + ":1", "box:1,1,1,0,0,0" + " " * 220_000,
                 "plane:0,0,0," + "\n" * 1000 + "1", "sphere:0.5,0.5,0.5,-" + "1" * 90):
        with pytest.raises(InputError) as raised:
            parse_shape(text)
        assert len(str(raised.value)) < 300 and str(raised.value).startswith("refine shape '"), str(raised.value)[:400]


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
        octree.leaves_octree(UNIT, levels, positions)
    assert type(raised.value) is InputError and str(raised.value).startswith(f"leaves: {needle}"), raised.value
    if len(levels) == 8 and not isinstance(positions, np.ndarray) and not isinstance(levels, np.ndarray) \
            and levels[0] is not True:  # (rows of ints with a bool are ints to numpy, and to build_mesh)
        rows = [[level, *position] for level, position in zip(levels, positions)]
        with pytest.raises(InputError):  # the API's rows: refused too, never truncated
            cospherical.build_mesh(domain=(1, 1, 1), leaves=rows, uniform=False)


def test_leaves_of_any_integer_type_are_accepted():
    expected = octree.leaves_octree(UNIT, [1] * 8, P8)
    for levels, positions in ((np.ones(8, dtype=np.uint8), np.array(P8, dtype=np.int16)),
                              ([np.int64(1)] * 8, [[np.int32(x) for x in p] for p in P8])):
        tree = octree.leaves_octree(UNIT, levels, positions)
        assert tree.levels.tolist() == expected.levels.tolist() and tree.positions.tolist() == expected.positions.tolist()


@pytest.mark.parametrize("shape, outside", [
    ("point:2,0.5,0.5", True), ("point:0.5,0.5,-0.001", True), ("box:1.01,0,0,2,1,1", True),
    ("sphere:3,3,3,1", True), ("sphere:0.5,0.5,0.5,5", True),  # a sphere around the whole domain meets none of it
    ("plane:1,0,0,1.5", True), ("plane:0,0,1,-1/3", True),
    ("point:1,1,1", False), ("box:1,0,0,2,1,1", False), ("sphere:2,0.5,0.5,1", False),  # touching counts
    ("plane:1,1,1,3", False), ("sphere:0.5,0.5,0.5,0.2", False),
])
def test_a_shape_that_does_not_meet_the_domain_warns_once(shape, outside):
    import warnings

    from cospherical.errors import CosphericalWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        tree = build_octree(UNIT, 2, [parse_shape(shape), parse_shape("point:0.1,0.1,0.1")])
    said = [str(w.message) for w in caught if issubclass(w.category, CosphericalWarning)]
    assert said == ([f"refine shape {shape!r} does not meet the domain: it refines nothing"] if outside else [])
    alone = build_octree(UNIT, 2, [parse_shape("point:0.1,0.1,0.1")])
    assert (len(tree) == len(alone)) == outside or not outside and len(tree) >= len(alone)
