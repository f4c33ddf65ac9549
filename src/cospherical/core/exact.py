"""Exact numbers for box lengths and Steiner parameters.

Box lengths are square roots of positive rationals, which covers integers,
decimals (``1.4142`` is the rational 7071/5000), fractions and ``sqrt(2)``.
Only squared lengths ever enter a predicate (see :mod:`cospherical.core.geometry`),
so every decision stays in rational arithmetic.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from fractions import Fraction

from ..errors import InputError, shown

__all__ = ["Length", "MAX_DIGITS", "NUMBER", "bounded", "parse_rational", "rational_text"]


_SQRT = re.compile(r"^(?:(?P<factor>[^*]+)\*)?sqrt\((?P<radicand>[^()]+)\)$")
# The one number grammar (ASCII only): an integer, a decimal, either with an
# exponent, or a fraction of two integers; an optional sign.  ``re.ASCII`` keeps
# \d from matching other scripts' digits (Arabic-Indic, fullwidth, ...).
NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d+)?(?:[eE][+-]?\d+)?|\d+/\d+)", re.ASCII)
# Bounds that keep every exact computation small: at most MAX_DIGITS digits in
# the numerator and in the denominator (1e-40 and 10^40 are fine; 1e400 is not).
MAX_DIGITS = 40
_MAX_TEXT = 100


def parse_rational(text: object, what: str = "number") -> Fraction:
    """Parse an integer, decimal or fraction exactly (the ASCII grammar :data:`NUMBER`, bounded size).

    Examples
    --------
    >>> parse_rational("1.4142")
    Fraction(7071, 5000)
    >>> parse_rational("3/2")
    Fraction(3, 2)
    >>> parse_rational("\u0663/\u0662")
    Traceback (most recent call last):
    ...
    cospherical.errors.InputError: number '٣/٢': not an integer, decimal or fraction (ASCII digits)
    """
    if isinstance(text, (int, Fraction)) and not isinstance(text, bool):
        return bounded(Fraction(text), what, text)
    if isinstance(text, float):
        raise InputError(f"{what} {shown(text)}: give an exact value (a string such as '0.5' or '1/3'), not a float")
    if not isinstance(text, str):
        raise InputError(f"{what} {shown(text)}: not a number")
    cleaned = text.strip(" \t")
    if len(cleaned) > _MAX_TEXT:
        raise InputError(f"{what} {shown(text)}: too long ({len(cleaned)} characters; at most {_MAX_TEXT})")
    if not NUMBER.fullmatch(cleaned):
        raise InputError(f"{what} {shown(text)}: not an integer, decimal or fraction (ASCII digits)")
    mantissa, _, exponent = cleaned.lower().partition("e")
    if exponent and abs(int(exponent)) > MAX_DIGITS + _MAX_TEXT:  # before computing 10**exponent
        raise InputError(f"{what} {shown(text)}: too large or too small (at most {MAX_DIGITS} digits)")
    try:
        value = Fraction(cleaned)
    except ZeroDivisionError:
        raise InputError(f"{what} {shown(text)}: division by zero") from None
    return bounded(value, what, text)


def bounded(value: Fraction, what: str, text: object) -> Fraction:
    """``value``, when its numerator and denominator have at most :data:`MAX_DIGITS` digits each."""
    limit = 10**MAX_DIGITS
    if abs(value.numerator) >= limit or value.denominator >= limit:
        raise InputError(f"{what} {shown(text)}: too large or too precise (at most {MAX_DIGITS} digits in the "
                         "numerator and in the denominator)")
    return value


def rational_text(value: Fraction) -> str:
    """Shortest exact text of a rational: ``1``, ``1.4142`` or ``1/3``.

    >>> rational_text(Fraction(7071, 5000)), rational_text(Fraction(1, 3))
    ('1.4142', '1/3')
    """
    if value.denominator == 1:
        return str(value.numerator)
    den = value.denominator
    twos = fives = 0
    while den % 2 == 0:
        den //= 2
        twos += 1
    while den % 5 == 0:
        den //= 5
        fives += 1
    if den == 1:  # a finite decimal
        digits = max(twos, fives)
        scaled = value * 10**digits
        sign = "-" if scaled < 0 else ""
        whole, frac = divmod(abs(scaled.numerator), 10**digits)
        text = f"{sign}{whole}.{frac:0{digits}d}"
        # 1/2**130 is a decimal of 132 characters, beyond what parse_rational reads back: a fraction then
        if len(text) <= _MAX_TEXT:
            return text
    return f"{value.numerator}/{value.denominator}"


def _exact_sqrt(value: Fraction) -> Fraction | None:
    num, den = math.isqrt(value.numerator), math.isqrt(value.denominator)
    if num * num == value.numerator and den * den == value.denominator:
        return Fraction(num, den)
    return None


@dataclass(frozen=True, order=True)
class Length:
    """A positive length known exactly through its square.

    Examples
    --------
    >>> Length.parse("sqrt(2)").squared
    Fraction(2, 1)
    >>> Length.parse("1.4142").text
    '1.4142'
    >>> Length.parse("2*sqrt(2)").text
    'sqrt(8)'
    """

    squared: Fraction

    def __post_init__(self) -> None:
        if self.squared <= 0:
            raise InputError(f"squared box length {self.squared}: must be > 0")

    @classmethod
    def parse(cls, text: str | int | Fraction, what: str = "box length") -> "Length":
        if isinstance(text, Length):
            return text
        if isinstance(text, str):
            cleaned = text.strip(" \t").replace(" ", "").lower()
            match = _SQRT.match(cleaned)
            if match:
                radicand = parse_rational(match["radicand"], what)
                factor = parse_rational(match["factor"], what) if match["factor"] else Fraction(1)
                if radicand <= 0 or factor <= 0:
                    raise InputError(f"{what} {text!r}: must be > 0")
                length = cls(factor * factor * radicand)
                # its text (the root, or sqrt of the square) is what files write and read back: within the bounds
                root = _exact_sqrt(length.squared)
                bounded(root if root is not None else length.squared, what, text)
                return length
        value = parse_rational(text, what)
        if value <= 0:
            raise InputError(f"{what} {text!r}: must be > 0")
        return cls(value * value)

    @property
    def text(self) -> str:
        root = _exact_sqrt(self.squared)
        if root is not None:
            return rational_text(root)
        return f"sqrt({rational_text(self.squared)})"

    def __float__(self) -> float:
        root = _exact_sqrt(self.squared)
        if root is not None:
            return float(root)
        return math.sqrt(self.squared.numerator / self.squared.denominator)

    def __str__(self) -> str:
        return self.text
