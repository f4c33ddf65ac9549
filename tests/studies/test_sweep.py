"""Aspect-ratio sweeps: exact grids of ratios, the study of each box (1, b, c) with b <= c, in grid order."""

from __future__ import annotations

from fractions import Fraction

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cospherical.errors import InputError
from cospherical.studies import sweep as sweeps
from cospherical.studies.sweep import box_statistics, grid_values, sweep


@given(st.fractions(min_value=Fraction(1, 100), max_value=100, max_denominator=100),
       st.fractions(min_value=0, max_value=10, max_denominator=100), st.integers(2, 12))
@settings(max_examples=40)
def test_a_grid_runs_evenly_from_min_to_max(low, width, steps):
    high = low + width
    values = grid_values(f"{low}:{high}:{steps}")
    assert len(values) == steps and values[0] == low and values[-1] == high
    assert len({b - a for a, b in zip(values, values[1:])}) == 1  # exact, evenly spaced


@pytest.mark.parametrize("spec, needle", [("1:2", "MIN:MAX:STEPS"), ("1:2:x", "whole number"), ("0:2:3", "0 < MIN"),
                                          ("2:1:3", "MIN <= MAX"), ("1:2:1", "STEPS = 1 only"), ("1:nan:3", "--b .nan.: not an integer")])
def test_a_bad_grid_is_one_line(spec, needle):
    with pytest.raises(InputError, match=needle):
        grid_values(spec, "--b")
    assert grid_values("3/2:3/2:1") == [Fraction(3, 2)]


def test_the_cube_is_the_papers_first_box():
    # The paper's Table 2 (box A): 37,259 elements, every one of the 4096 configurations FVM-adequate.
    stats = box_statistics(("1", "1", "1"))
    assert (stats["box"], stats["total"], stats["fvm_adequate"]) == (["1", "1", "1"], 37259, 4096)


def test_the_boxes_with_b_up_to_c_in_grid_order(monkeypatch):
    # On the first 64 codes of each box: which boxes, in which order, each box's own figures.
    codes = sweeps.bisection_codes()[:64]
    monkeypatch.setattr(sweeps, "bisection_codes", lambda: codes)
    done = []
    rows = sweep([Fraction(1), Fraction(3, 2)], [Fraction(1), Fraction(3, 2), Fraction(2)], progress=done.append)
    assert [row["box"] for row in rows] == [["1", "1", "1"], ["1", "1", "1.5"], ["1", "1", "2"],
                                            ["1", "1.5", "1.5"], ["1", "1.5", "2"]]
    assert done == [1] * 5 and rows[2] == box_statistics(("1", "1", "2"))
    assert len({(row["total"], row["types"]) for row in rows}) > 1  # the boxes differ
