"""Aspect-ratio sweeps: the bisection study over a grid of boxes (1, b, c)."""

from __future__ import annotations

from fractions import Fraction
from typing import Any, Callable, Iterable

from ..core.configuration import Box
from ..core.exact import parse_rational, rational_text
from ..errors import InputError
from .engine import bisection_codes, run_study
from ..execution.pool import process_pool

__all__ = ["box_statistics", "grid_values", "sweep"]


def grid_values(spec: str, what: str = "ratio range") -> list[Fraction]:
    """``MIN:MAX:STEPS`` -> STEPS exact values from MIN to MAX (both included).

    >>> [str(x) for x in grid_values("1:2:3")]
    ['1', '3/2', '2']
    """
    parts = spec.split(":")
    if len(parts) != 3:
        raise InputError(f"{what} {spec!r}: write MIN:MAX:STEPS, for example 1:2:5")
    low, high = (parse_rational(p, what) for p in parts[:2])
    try:
        steps = int(parts[2])
    except ValueError:
        raise InputError(f"{what} {spec!r}: STEPS must be a whole number") from None
    if low <= 0 or high < low or steps < 1 or (steps == 1 and high != low):
        raise InputError(f"{what} {spec!r}: need 0 < MIN <= MAX and STEPS >= 1 (STEPS = 1 only when MIN = MAX)")
    if steps == 1:
        return [low]
    return [low + (high - low) * i / (steps - 1) for i in range(steps)]


def box_statistics(lengths: tuple[str, str, str]) -> dict[str, Any]:
    """FVM-adequate configurations, element types and elements of one box's bisection study."""
    box = Box.parse(lengths)
    study = run_study("bisection", box, bisection_codes(), criteria=("optimal",))
    return {
        "box": list(box.texts),
        "fvm_adequate": study.fvm_adequate,
        "fvm_adequate_open": study.fvm_adequate_open,
        "types": len(study.type_counts()),
        "total": study.total(),
    }


def sweep(b_values: Iterable[Fraction], c_values: Iterable[Fraction], jobs: int = 1,
          progress: Callable[[int], None] | None = None) -> list[dict[str, Any]]:
    """Statistics of every box (1, b, c) of the grid with b <= c, in grid order."""
    boxes = [("1", rational_text(b), rational_text(c)) for b in b_values for c in c_values if b <= c]
    if jobs <= 1:
        results = []
        for lengths in boxes:
            results.append(box_statistics(lengths))
            if progress:
                progress(1)
        return results
    with process_pool(jobs) as pool:
        results = []
        for stats in pool.map(box_statistics, boxes):
            results.append(stats)
            if progress:
                progress(1)
        return results
