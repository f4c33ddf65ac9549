"""The intersection family (paper, section 5): Steiner points anywhere, at multiples of 1/R.

For each of the three sets of four parallel edges, a *pattern* says which edges
carry a point and the relative order of those points, ties allowed (an ordered
partition of the points into levels).  The paper's midpoint scheme turns levels
into positions: the first level inserted goes to 1/2; a level left of every
placed one goes halfway between 0 and the leftmost; right of every placed one,
halfway between the rightmost and 1; between two placed ones, halfway between
them.  The paper does not say in which order the levels are inserted, so the
order is a parameter:

``edge``      levels in the order their first point appears along the edge list;
``rank``      from the lowest level up;
``reverse``   from the highest level down.

m levels need positions down to 1/2^m, so at resolution R = 2^d only patterns
with at most d levels exist; at R = 16 every pattern (150 per set) does.
"""

from __future__ import annotations

from fractions import Fraction
from collections.abc import Iterator
from itertools import combinations, product

import numpy as np

from ...core.configuration import Box
from ...core.shapes import edge_axis
from ...core.symmetry import box_symmetries, orbit_keys
from ...errors import InputError
from ...choices import INSERTION_ORDERS, KeyBackend

__all__ = ["PARALLEL_EDGES", "all_configurations", "intersection_codes", "orbits", "set_patterns"]

PARALLEL_EDGES = tuple(tuple(k for k in range(12) if edge_axis(k) == axis) for axis in range(3))


def _ordered_partitions(k: int) -> Iterator[tuple[int, ...]]:
    """Every surjection of k points onto levels 0..m-1 (weak orders of k items)."""
    for m in range(1, k + 1):
        for levels in product(range(m), repeat=k):
            if len(set(levels)) == m:
                yield levels


def _positions(levels: tuple[int, ...], order: str) -> dict[int, Fraction]:
    m = max(levels) + 1
    if order == "edge":
        sequence = list(dict.fromkeys(levels))
    elif order == "rank":
        sequence = list(range(m))
    elif order == "reverse":
        sequence = list(range(m - 1, -1, -1))
    else:
        raise InputError(f"insertion order {order!r}: choose one of {', '.join(INSERTION_ORDERS)}")
    placed: dict[int, Fraction] = {}
    for level in sequence:
        below = [t for other, t in placed.items() if other < level]
        above = [t for other, t in placed.items() if other > level]
        low = max(below) if below else Fraction(0)
        high = min(above) if above else Fraction(1)
        placed[level] = (low + high) / 2
    return placed


def set_patterns(resolution: int = 16, order: str = "edge") -> list[tuple[int, int, int, int]]:
    """Every pattern of one set of four parallel edges, as 16ths (0 = no point), sorted.

    >>> len(set_patterns(16)), len(set_patterns(2))
    (150, 16)
    """
    if resolution < 2 or resolution & (resolution - 1) or resolution > 16:
        raise InputError(f"resolution {resolution}: a power of two from 2 to 16")
    depth = resolution.bit_length() - 1
    patterns: set[tuple[int, int, int, int]] = set()
    for k in range(5):
        for carriers in combinations(range(4), k):
            for levels in _ordered_partitions(k) if k else [()]:
                if levels and max(levels) + 1 > depth:
                    continue
                digits = [0, 0, 0, 0]
                if levels:
                    where = _positions(levels, order)
                    for edge, level in zip(carriers, levels):
                        digits[edge] = int(where[level] * 16)
                patterns.add((digits[0], digits[1], digits[2], digits[3]))
    return sorted(patterns)


def intersection_codes(resolution: int = 16, order: str = "edge") -> np.ndarray:
    """All configurations as an (N, 12) array of hex digits, one row per configuration code."""
    patterns = np.array(set_patterns(resolution, order), dtype=np.uint8)
    n = len(patterns)
    grid = np.zeros((n, n, n, 12), dtype=np.uint8)
    for axis, edges in enumerate(PARALLEL_EDGES):
        shape = [1, 1, 1, 4]
        shape[axis] = n
        view = patterns.reshape(shape)
        grid[..., list(edges)] = view
    return grid.reshape(-1, 12)


def orbits(resolution: int = 16, order: str = "edge", backend: KeyBackend = "compiled") -> tuple[np.ndarray, np.ndarray, int]:
    """Orbit representatives (codes as base-16 numbers, sorted) with their sizes, and the configuration count.

    The family is not closed under the cube's symmetries (a reflected configuration
    has positions 1 - t, which the midpoint scheme does not produce), so an orbit
    here collects only the family's members that map onto each other.

    ``backend``: the orbit keys' (:func:`cospherical.core.symmetry.orbit_keys`);
    the compiled kernel by default, since the study and its tables load it for
    their bulk work anyway (hundreds of thousands of codes from R = 4 on).
    """
    digits = intersection_codes(resolution, order)
    keys, _ = orbit_keys(digits, box_symmetries(Box.parse(["1", "1", "1"])), backend)
    reps, sizes = np.unique(keys, return_counts=True)
    return reps, sizes, len(digits)


def all_configurations(resolution: int = 16, order: str = "edge") -> np.ndarray:
    """Every configuration's code as a base-16 number, sorted (the brute-force run, no orbits)."""
    digits = intersection_codes(resolution, order).astype(np.int64)
    return np.sort((digits << (4 * np.arange(11, -1, -1))).sum(axis=1))
