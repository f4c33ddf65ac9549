"""Refinement shapes: the exact cell tests against a brute force in fractions, the size bound and the leaf
estimate, and a shape text of any length named cut short."""

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
from cospherical.mesh import refinement
from cospherical.mesh.refinement import Shape, parse_shape


def _brute_meets(shape: Shape, box: Box, level: int, cell) -> bool:
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
        shape = parse_shape(text)
        n = 1 << level
        cells = np.array([(i, j, k) for i in range(n) for j in range(n) for k in range(n)], dtype=np.int64)
        hits = refinement.meets_shape(shape, box, level, cells)
    except Exception as error:  # only the library's own refusal (a sphere over a sqrt length, a bad radius)
        assert type(error).__name__ == "InputError", error
        return
    expected = [_brute_meets(shape, box, level, tuple(cell)) for cell in cells.tolist()]
    assert hits.tolist() == expected
    bound = refinement._hits_bound(shape, box, level)
    assert int(hits.sum()) <= bound
    if shape.kind == "box":
        assert int(hits.sum()) == bound
    # the estimate bounds the unbalanced refinement's leaves
    assert refinement.estimate_leaves(box, level, [shape]) >= 1 + 7 * sum(
        int(refinement.meets_shape(shape, box, m, np.array([(i, j, k) for i in range(1 << m) for j in range(1 << m)
                                                   for k in range(1 << m)], dtype=np.int64)).sum())
        for m in range(level))


def test_a_shape_text_of_any_length_is_named_cut_short():
    # from the API as from --refine: a 220 kB shape text was echoed whole in the error
    for text in ("sphere:" + "1" * 220_000 + ",0,0,1", "x" * 220_000 + ":1", "box:1,1,1,0,0,0" + " " * 220_000,
                 "plane:0,0,0," + "\n" * 1000 + "1", "sphere:0.5,0.5,0.5,-" + "1" * 90):
        with pytest.raises(InputError) as raised:
            parse_shape(text)
        assert len(str(raised.value)) < 300 and str(raised.value).startswith("refine shape '"), str(raised.value)[:400]
