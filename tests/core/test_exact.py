"""Exact numbers: the number grammar (``parse_rational``) and box lengths (``Length``), fuzzed.

Counts (max_examples): number grammar 2000, box lengths 2500 with ``pytest --full``; a quarter of
each by default (``sampling.examples``: fresh inputs every run).
"""

from __future__ import annotations

import re

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from sampling import examples

from cospherical import InputError, Length
from cospherical.core.exact import parse_rational


# The number grammar, written again here as the oracle: ASCII digits only, an optional sign, an
# integer or decimal with an optional exponent, or a fraction; at most 40 digits above and below.
ORACLE = re.compile(r"[+-]?([0-9]+(\.[0-9]+)?([eE][+-]?[0-9]+)?|[0-9]+/[0-9]+)")
# characters that look like digits, signs or spaces to a person but are not ASCII
LOOKALIKES = "\u0661\u0662\u0663\u06f1\u0967\uff10\uff11\uff12\u00b2\u2212\u00a0\u2009\uff0f\u2044_"


def fuzz(n: int):
    return settings(max_examples=examples(n), deadline=None, suppress_health_check=list(HealthCheck))


@fuzz(2000)
@given(st.one_of(st.text(alphabet="0123456789+-./eE " + LOOKALIKES, max_size=14),
                 st.from_regex(r"\A[+-]?[0-9]{1,45}(\.[0-9]{1,45})?([eE][+-]?[0-9]{1,3})?\Z"),
                 st.from_regex(r"\A[0-9]{1,45}/[0-9]{1,45}\Z")))
def test_number_grammar(text):
    """parse_rational accepts exactly the ASCII grammar with bounded digits, and reads it exactly."""
    from fractions import Fraction

    cleaned = text.strip(" ")
    try:
        value = parse_rational(text)
    except InputError as error:
        assert str(error).startswith("number ")
        if ORACLE.fullmatch(cleaned) and "e" not in cleaned.lower() and not cleaned.endswith("/0") \
                and not re.fullmatch(r"[+-]?0+/0+|.*/0+", cleaned):
            exact = Fraction(cleaned)
            assert abs(exact.numerator) >= 10**40 or exact.denominator >= 10**40, (text, error)
    else:
        assert ORACLE.fullmatch(cleaned), text
        assert value == Fraction(cleaned)
        assert abs(value.numerator) < 10**40 and value.denominator < 10**40


@fuzz(2500)
@given(st.one_of(st.text(max_size=20),
                 st.from_regex(r"\A-?[0-9]{0,4}(\.[0-9]{0,4})?(/[0-9]{0,3})?\Z"),
                 st.from_regex(r"\A([0-9./]{1,5}\*)?sqrt\([-0-9./ ]{0,6}\)\Z")))
def test_box_lengths(text):
    try:
        length = Length.parse(text)
    except InputError as error:
        assert "box length" in str(error)
    else:
        assert length.squared > 0 and float(length) > 0
        assert Length.parse(length.text) == length


@fuzz(400)
@given(st.integers(1, 10**40 - 1), st.integers(0, 140), st.integers(0, 60), st.booleans(),
       st.sampled_from(["", "2", "3", "7/5", "1/1024", "9" * 39, "1/" + "7" * 39]))
def test_a_length_is_read_back_from_its_text(numerator, twos, fives, small, radicand):
    """What files write of a length (its ``text``: the domain of dual.npz, report.json, mesh.vtu) reads back
    as the same length, or the length is refused when given: 1/2**130 was written as a decimal of 132
    characters, 9...9*sqrt(2) as the square root of an 80-digit number, both beyond what the reader takes."""
    from fractions import Fraction

    value = Fraction(numerator, 2**twos * 5**fives) if small else Fraction(2**twos * 5**fives, numerator)
    text = f"{value}*sqrt({radicand})" if radicand else str(value)
    try:
        length = Length.parse(text)
    except InputError as error:
        assert "too large or too precise" in str(error) or "too long" in str(error), (text, error)
        return
    assert Length.parse(length.text) == length, (text, length.text)
