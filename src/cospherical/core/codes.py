"""Configuration codes: every encoding of a configuration as text, in one place.

A code has one hexadecimal digit per edge of the base element: digit k is
``0`` where edge k carries no Steiner point and ``n`` where it carries one at
t = n/16 from the edge's lower end.  A point set may name its face and body
points in a suffix: ``+f``, the faces carrying a point in increasing order,
then ``b`` for the body point (``888888888888+f04``); one point set,
one code, since pattern tables are looked up by the code's text.  A symmetry
that reverses an edge sends digit n to 16 - n.  The intersection study keys
the 12 digits of a cuboid code as one base-16 number.

Examples
--------
>>> digit_parameters("80c")
(Fraction(1, 2), None, Fraction(3, 4))
>>> parameter_digits(digit_parameters("80c"))
'80c'
>>> point_suffix({4, 0}, False), point_suffix(range(6), True), point_suffix((), False)
('f04', 'f012345b', 'f')
"""

from __future__ import annotations

import re
from fractions import Fraction
from typing import TYPE_CHECKING, Iterable, Sequence

from ..caches import cached
from ..errors import InputError, shown

if TYPE_CHECKING:
    import numpy as np

__all__ = ["REVERSED_DIGIT", "code_digits", "digit_parameters", "edge_code_pattern", "key_code", "mask_code",
           "mask_codes", "parameter_digits", "parse_point_suffix", "point_suffix"]

_SUFFIX = re.compile(r"^f(?P<faces>[0-9]*)(?P<body>b?)$")
# The digit of the same point seen from the edge's other end.
REVERSED_DIGIT = {"%x" % n: "%x" % ((16 - n) % 16) for n in range(16)}


@cached(maxsize=16)
def edge_code_pattern(edges: int) -> re.Pattern[str]:
    """The codes of an element with ``edges`` edges: that many digits and an optional point suffix.

    >>> edge_code_pattern(6).match("800000+f")["suffix"]
    'f'
    """
    return re.compile(rf"^(?P<edges>[0-9a-fA-F]{{{edges}}})(?:\+(?P<suffix>.*))?$", re.DOTALL)


def digit_parameters(digits: str) -> tuple[Fraction | None, ...]:
    """The Steiner parameter of each edge digit (``None``: no point); the digits are checked by the caller."""
    return tuple(Fraction(int(ch, 16), 16) if ch != "0" else None for ch in digits)


def parameter_digits(parameters: Iterable[Fraction | None]) -> str | None:
    """The edge digits of Steiner parameters; ``None`` when some t is not a multiple of 1/16."""
    digits = []
    for t in parameters:
        if t is None:
            digits.append("0")
        elif (t * 16).denominator == 1:
            digits.append("%x" % int(t * 16))
        else:
            return None
    return "".join(digits)


def parse_point_suffix(code: str, suffix: str) -> tuple[frozenset[int], bool]:
    """The faces and body point named by a code's point suffix (the text after ``+``).

    Examples
    --------
    >>> parse_point_suffix("888888888888+f04", "f04")
    (frozenset({0, 4}), False)
    >>> parse_point_suffix("888888888888+f40", "f40")
    Traceback (most recent call last):
    ...
    cospherical.errors.InputError: configuration code '888888888888+f40': list the faces of the suffix in increasing order (+f04)
    """
    match = _SUFFIX.match(suffix)
    if not match:
        raise InputError(f"configuration code {shown(code)}: malformed point suffix {shown('+' + suffix)}: write +f, then "
                         "the faces carrying a point (0..5 on a cuboid, increasing), then b for the body point, "
                         "e.g. +f04")
    digits = match["faces"]
    if len(set(digits)) != len(digits):
        raise InputError(f"configuration code {shown(code)}: a face is given twice in the suffix")
    if list(digits) != sorted(digits):
        # one point set, one code: pattern tables are looked up by the code's text
        raise InputError(f"configuration code {shown(code)}: list the faces of the suffix in increasing order "
                         f"(+f{''.join(sorted(digits))})")
    return frozenset(int(d) for d in digits), bool(match["body"])


def point_suffix(faces: Iterable[int], body: bool) -> str:
    """The point suffix (without ``+``) naming a set of face points and the body point."""
    return "f" + "".join(str(f) for f in sorted(faces)) + ("b" if body else "")


def mask_code(mask: int, edges: int) -> str:
    """The bisection code with a midpoint (``8``) on the edges whose bit is set in ``mask``.

    Examples
    --------
    >>> mask_code(0b101, 4)
    '8080'
    """
    return "".join("8" if mask >> k & 1 else "0" for k in range(edges))


def mask_codes(edges: int) -> list[str]:
    """The bisection codes of an element with ``edges`` edges: a midpoint (``8``) or nothing on each.

    Examples
    --------
    >>> mask_codes(2)
    ['00', '80', '08', '88']
    """
    return [mask_code(mask, edges) for mask in range(1 << edges)]


def key_code(key: int) -> str:
    """The 12 edge digits whose base-16 number is ``key`` (the intersection study's keys).

    Examples
    --------
    >>> key_code(0x48)
    '000000000048'
    """
    return "%012x" % key


def code_digits(codes: Sequence[str]) -> np.ndarray:
    """The 12 edge digits of each code as a row of integers 0..15 (any point suffix left aside)."""
    import numpy as np

    text = np.frombuffer("".join(code[:12] for code in codes).lower().encode("ascii"), dtype=np.uint8).reshape(-1, 12)
    return np.where(text >= ord("a"), text - ord("a") + 10, text - ord("0")).astype(np.int64)
