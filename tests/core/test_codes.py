"""Configuration codes: every encoding round-trips, and a suffix has one spelling."""

from __future__ import annotations

from fractions import Fraction

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cospherical import Configuration, InputError
from cospherical.core.codes import (REVERSED_DIGIT, code_digits, digit_parameters, key_code, mask_codes,
                                    parameter_digits, parse_point_suffix, point_suffix)

DIGITS = st.text(alphabet="0123456789abcdef", min_size=12, max_size=12)


@settings(max_examples=100, deadline=None)
@given(DIGITS, st.sets(st.integers(0, 5)), st.booleans())
def test_codes_round_trip_through_every_encoding(digits, faces, body):
    assert parameter_digits(digit_parameters(digits)) == digits
    assert key_code(int(digits, 16)) == digits  # the intersection study's keys
    assert code_digits([digits + "+" + point_suffix(faces, body)]).tolist() == [[int(d, 16) for d in digits]]
    assert parse_point_suffix(digits, point_suffix(faces, body)) == (frozenset(faces), body)
    # a digit seen from the edge's other end: t becomes 1 - t
    for d in digits:
        t = digit_parameters(d)[0]
        assert digit_parameters(REVERSED_DIGIT[d])[0] == (None if t is None else 1 - t)


def test_a_parameter_off_the_sixteenths_has_no_code():
    assert parameter_digits([Fraction(1, 3)]) is None
    assert parameter_digits([Fraction(3, 16), None]) == "30"


@pytest.mark.parametrize("suffix, needle", [("f40", "increasing order (+f04)"), ("f00", "given twice"),
                                             ("x1", "malformed point suffix"), ("f0bb", "malformed point suffix")])
def test_a_suffix_has_one_spelling(suffix, needle):
    with pytest.raises(InputError, match=needle.replace("(", r"\(").replace(")", r"\)").replace("+", r"\+")):
        parse_point_suffix("888888888888+" + suffix, suffix)
    with pytest.raises(InputError, match="configuration code"):  # the same rule where users meet it
        Configuration.from_code("888888888888+" + suffix)


def test_bisection_codes_are_every_mask_once():
    codes = mask_codes(12)
    assert len(codes) == len(set(codes)) == 4096
    assert all(set(code) <= {"0", "8"} for code in codes) and codes[0] == "0" * 12 and codes[-1] == "8" * 12
