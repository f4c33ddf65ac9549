"""Refinement shapes in domain units, and which cells of a level they meet, decided exactly.

A shape (``sphere``, ``plane``, ``point``, ``box``) is read exactly (:func:`parse_shape`:
rational numbers); whether a cell's closed box meets it is decided with integers:
shape coordinates are exact rationals, squared lengths are rationals, and the
comparisons are cleared of denominators before they are made (no tolerance).  How
many cells a shape can meet is bounded without visiting them (:func:`estimate_leaves`),
so an octree too large for the machine is refused before it is built.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Sequence

import numpy as np
from numpy.typing import NDArray

from ..core.configuration import Box
from ..core.exact import parse_rational
from ..errors import InputError, shown

__all__ = ["Shape", "estimate_leaves", "meets_shape", "parse_shape"]

_SHAPE_FORMS = {
    "sphere": ("X,Y,Z,R", 4),
    "plane": ("NX,NY,NZ,D", 4),
    "point": ("X,Y,Z", 3),
    "box": ("X0,Y0,Z0,X1,Y1,Z1", 6),
}


@dataclass(frozen=True)
class Shape:
    """A refinement shape in domain units, exact: ``kind`` and its rational ``values``.

    Examples
    --------
    >>> parse_shape("sphere:0.5,0.5,0.5,0.3")
    Shape(kind='sphere', values=(Fraction(1, 2), Fraction(1, 2), Fraction(1, 2), Fraction(3, 10)), text='sphere:0.5,0.5,0.5,0.3')
    """

    kind: str
    values: tuple[Fraction, ...]
    text: str


def parse_shape(text: str) -> Shape:
    """Read ``sphere:X,Y,Z,R``, ``plane:NX,NY,NZ,D``, ``point:X,Y,Z`` or ``box:X0,Y0,Z0,X1,Y1,Z1``.

    Numbers are exact rationals (``0.3`` is 3/10, ``1/3``); a bad shape raises
    :class:`~cospherical.errors.InputError` naming it.

    Examples
    --------
    >>> parse_shape("point:0.3,0.61,0.77").values[1]
    Fraction(61, 100)
    >>> parse_shape("cone:1,2")
    Traceback (most recent call last):
    ...
    cospherical.errors.InputError: refine shape 'cone:1,2': unknown kind 'cone'; write sphere:X,Y,Z,R, plane:NX,NY,NZ,D, point:X,Y,Z or box:X0,Y0,Z0,X1,Y1,Z1
    """
    kind, sep, rest = str(text).partition(":")
    kind = kind.strip().lower()
    forms = ", ".join(f"{k}:{form}" for k, (form, _) in _SHAPE_FORMS.items())
    forms = forms.replace(", box", " or box")
    if not sep or kind not in _SHAPE_FORMS:
        what = f"unknown kind {shown(kind)}" if sep else "no kind"
        raise InputError(f"refine shape {shown(text)}: {what}; write {forms}")
    form, count = _SHAPE_FORMS[kind]
    parts = [p for p in rest.split(",")]
    if len(parts) != count:
        raise InputError(f"refine shape {shown(text)}: {kind} needs {count} numbers {form}, got {len(parts)}")
    values = tuple(parse_rational(p.strip(), f"refine shape {shown(text)}: number") for p in parts)
    if kind == "sphere" and values[3] <= 0:
        raise InputError(f"refine shape {shown(text)}: the radius must be positive")
    if kind == "plane" and not any(values[:3]):
        raise InputError(f"refine shape {shown(text)}: the normal (NX,NY,NZ) must not be zero")
    if kind == "box" and any(values[a] > values[a + 3] for a in range(3)):
        raise InputError(f"refine shape {shown(text)}: needs X0 <= X1, Y0 <= Y1, Z0 <= Z1")
    return Shape(kind, values, str(text))


def _rational_lengths(box: Box, shape: Shape) -> tuple[Fraction, Fraction, Fraction]:
    lengths = []
    for length in box.lengths:
        root = Fraction(math.isqrt(length.squared.numerator), math.isqrt(length.squared.denominator))
        if root * root != length.squared:
            # A sphere or plane over a sqrt length compares sums of unlike square roots:
            # refuse rather than decide with floats.
            raise InputError(f"refine shape {shown(shape.text)}: {shape.kind} needs rational domain lengths, "
                             f"got {length.text}; use point or box shapes, or --leaves")
        lengths.append(root)
    return lengths[0], lengths[1], lengths[2]


def _exact_array(values: NDArray[np.integer[Any]], bound: int) -> NDArray[Any]:
    """Integers as int64 when products up to ``bound`` fit, else as Python ints (object)."""
    return np.asarray(values, dtype=np.int64 if bound < 2**62 else object)


def _axis_range(squared: Fraction, lo: Fraction, hi: Fraction, level: int) -> tuple[int, int]:
    """The first and last cell index ``i`` at ``level`` whose span ``[i, i+1] * len / 2**level`` meets
    ``[lo, hi]`` on an axis of length ``len = sqrt(squared)``; empty when first > last.

    Decided in Python integers, once per axis: ``i * len <= hi * 2**level`` holds exactly for
    ``i <= floor(sqrt(hi**2 * 4**level / squared))`` (``i`` is an integer), and likewise below, so
    the cells are compared with two integers that fit any array (no product can overflow).
    """
    n = 1 << level
    top = hi * n
    last = -1 if top < 0 else math.isqrt(math.floor(top * top / squared))
    bottom = lo * n
    if bottom <= 0:
        first = 0
    else:  # (i + 1) * len >= bottom: i + 1 >= ceil(sqrt(bottom**2 / squared))
        need = math.ceil(bottom * bottom / squared)
        first = math.isqrt(need - 1)
    return max(first, 0), min(last, n - 1)


def _plane_coefficients(shape: Shape, box: Box) -> tuple[list[int], Fraction]:
    """A plane ``n . x = D`` over the domain as integers ``k`` and ``D'`` with ``k . (s, t, u) = D'``
    in the unit frame (``x = (s*A, t*B, u*C)``)."""
    v = shape.values
    lengths = _rational_lengths(box, shape)
    coeff = [v[a] * lengths[a] for a in range(3)]
    den = math.lcm(*(x.denominator for x in coeff), v[3].denominator)
    return [int(x * den) for x in coeff], v[3] * den


def meets_shape(shape: Shape, box: Box, level: int, cells: NDArray[np.integer[Any]]) -> NDArray[np.bool_]:
    """Which cells (n x 3 positions at ``level``) have a closed box meeting the shape, exactly.

    Everything is scaled to integers: on a grid of ``M * 2**level`` steps per side, where M
    clears the shape's denominators, a cell spans ``[i*M, (i+1)*M]`` per axis.  Arrays are
    int64 where a bound shows the products fit, else Python integers.
    """
    v = shape.values
    if shape.kind in ("point", "box"):
        lo, hi = (v[:3], v[:3]) if shape.kind == "point" else (v[:3], v[3:])
        inside = np.ones(len(cells), dtype=bool)
        for axis, length in enumerate(box.lengths):
            first, last = _axis_range(length.squared, lo[axis], hi[axis], level)
            inside &= (cells[:, axis] >= first) & (cells[:, axis] <= last)
        return inside
    lengths = _rational_lengths(box, shape)
    if shape.kind == "sphere":
        center, radius = v[:3], v[3]
        # unit-frame centre c = X / len; distances squared weigh each axis by len**2.
        unit = [center[a] / lengths[a] for a in range(3)]
        den = math.lcm(*(u.denominator for u in unit))
        grid = den * 2**level  # cell [i, i+1] is [i*den, (i+1)*den] on this grid
        weights_den = math.lcm(*(length.denominator ** 2 for length in lengths), radius.denominator ** 2)
        weights = [int(length * length * weights_den) for length in lengths]
        c = [int(u * grid) for u in unit]
        r2 = radius * radius * weights_den * grid * grid  # an integer: R**2 on the grid, weighted like the axes
        assert r2.denominator == 1
        extent = max(abs(x) for x in c) + grid
        fit = max(extent * extent * sum(weights) * 4, int(r2))
        near = np.zeros(len(cells), dtype=object if fit >= 2**62 else np.int64)
        far = np.zeros_like(near)
        for axis in range(3):
            start = _exact_array(cells[:, axis], fit) * den
            end = start + den
            ca = c[axis]
            # nearest point of [start, end] to ca, and the farther end
            d_near = np.where(ca < start, start - ca, np.where(ca > end, ca - end, 0))
            d_far = np.maximum(np.abs(start - ca), np.abs(end - ca))
            near = near + weights[axis] * d_near * d_near
            far = far + weights[axis] * d_far * d_far
        radius2 = int(r2)
        inside_far: NDArray[np.bool_] = (near <= radius2) & (radius2 <= far)
        return inside_far
    k, plane_rhs = _plane_coefficients(shape, box)
    scaled = plane_rhs * 2**level  # compare sum k_a * i_a with D * den * 2**l
    assert scaled.denominator == 1
    rhs = int(scaled)
    fit = (sum(abs(x) for x in k) + 1) * 2 ** (level + 1) + abs(rhs)
    low = np.zeros(len(cells), dtype=object if fit >= 2**62 else np.int64)
    high = np.zeros_like(low)
    for axis in range(3):
        i = _exact_array(cells[:, axis], fit)
        a, b = k[axis] * i, k[axis] * (i + 1)
        low = low + np.minimum(a, b)
        high = high + np.maximum(a, b)
    crossing: NDArray[np.bool_] = (low <= rhs) & (rhs <= high)
    return crossing


def _hits_bound(shape: Shape, box: Box, level: int) -> int:
    """An upper bound on the cells at ``level`` whose closed box meets the shape, without visiting them.

    A point meets at most 8 cells; a box exactly the product of its per-axis ranges; a
    plane, in the column of cells along its steepest axis, at most the cells an interval
    of its rise across one column meets.  A sphere's cells lie in the shell of one cell
    diagonal around it (a volume bound), and its surface, cut into six patches where one
    normal component is largest, rises at most one cell width per column (a column
    bound): the smaller of the two.  Only a size estimate is computed with floats here;
    which cells meet a shape is decided exactly by :func:`meets_shape`.
    """
    n = 1 << level
    if shape.kind == "point":
        return min(8, n**3)
    if shape.kind == "box":
        count = 1
        for axis, length in enumerate(box.lengths):
            first, last = _axis_range(length.squared, shape.values[axis], shape.values[axis + 3], level)
            count *= max(0, last - first + 1)
        return count
    if not bool(meets_shape(shape, box, 0, np.zeros((1, 3), dtype=np.int64))[0]):
        return 0
    if shape.kind == "plane":
        k = [abs(x) for x in _plane_coefficients(shape, box)[0]]
        steep = k.index(max(k))
        rise = (sum(k) - k[steep]) // k[steep] + 2
        # the columns along the steepest axis that the plane crosses inside the domain, counted
        # exactly at a coarse level: each holds 4**(level - coarse) columns of the level
        coarse = min(level, 5)
        m = 1 << coarse
        cells = np.stack(np.meshgrid(*([np.arange(m, dtype=np.int64)] * 3), indexing="ij"), axis=-1).reshape(-1, 3)
        hit = cells[meets_shape(shape, box, coarse, cells)]
        columns = len(np.unique(np.delete(hit, steep, axis=1), axis=0))
        return int(min(n**3, columns * 4 ** (level - coarse) * rise))
    sizes = [x / n for x in box.to_float()]
    diagonal = math.sqrt(sum(h * h for h in sizes))
    radius = float(shape.values[3])
    shell = 4 / 3 * math.pi * ((radius + diagonal) ** 3 - max(0.0, radius - diagonal) ** 3)
    column_bound = math.fsum(2 * n * n * ((sizes[(a + 1) % 3] + sizes[(a + 2) % 3]) / sizes[a] + 2) for a in range(3))
    return min(n**3, math.ceil(min(shell / math.prod(sizes), column_bound)) + 1)


def estimate_leaves(box: Box, levels: int, shapes: Sequence[Shape]) -> int:
    """The leaves :func:`build_octree` would make, estimated in milliseconds from the shapes alone.

    Every split adds seven leaves; the cells split at a level are at most those meeting
    a shape there (:func:`_hits_bound`), and balancing adds about as many again as a
    fraction of them (measured: at most 1.3 times on spheres and planes).
    """
    split = sum(min(1 << (3 * level), sum(_hits_bound(shape, box, level) for shape in shapes)) for level in range(levels))
    return 1 + 7 * split
