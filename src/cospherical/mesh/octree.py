"""A 1-irregular octree over a box domain: refined by shapes and balanced, or brought as a list of leaves.

A cell at level ``l`` is the integer position ``(i, j, k)`` with ``0 <= i, j, k < 2**l``;
its box in unit coordinates of the domain is ``[i/2**l, (i+1)/2**l] x ...``, the real
box that times the domain lengths (A, B, C).  Every decision (does a cell meet a
shape, do the leaves tile the domain, is the tree balanced) is made with integers:
shape coordinates are exact rationals, squared lengths are rationals, and the
comparisons are cleared of denominators before they are made (no tolerance).

The tree is held as arrays, level by level, never as Python objects per cell:
``split[l]`` holds the sorted linear keys ``(i * 2**l + j) * 2**l + k`` of the cells of
level ``l`` that are split.  A tree is 2:1 balanced exactly when every neighbour
(same level) of a split cell exists, i.e. its parent is split; that closure, taken
from the finest level down, is the coarsest balanced tree containing the refinement.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from fractions import Fraction
from itertools import product
from typing import Callable, Sequence

import numpy as np

from ..choices import BALANCES, Balance
from ..core.configuration import Box
from ..core.exact import parse_rational
from ..errors import CosphericalWarning, InputError, shown
from ..files.yamlio import machine_memory

__all__ = ["BYTES_PER_LEAF", "MAX_LEVEL", "Octree", "Shape", "build_octree", "check_leaf_count", "distinct",
           "estimate_leaves", "leaf_bound", "leaf_list_order", "leaves_octree", "parse_shape"]

MAX_LEVEL = 16  # keys (2**16)**3 and the half-spacing grid (2**17 + 1)**3 stay inside int64
# Balance across faces alone is not among them: it is not 1-irregular (an edge can get two points).
# Peak memory of `cospherical mesh` with every check, per leaf: 1.5 kB measured at 131,258
# leaves (plane:1,1,1,1.5, levels 7); rounded up.
BYTES_PER_LEAF = 2048
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
    return tuple(lengths)


def _exact_array(values: Sequence[int], bound: int) -> np.ndarray:
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


def _meets(shape: Shape, box: Box, level: int, cells: np.ndarray) -> np.ndarray:
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
            lo = _exact_array(cells[:, axis], fit) * den
            hi = lo + den
            ca = c[axis]
            # nearest point of [lo, hi] to ca, and the farther end
            d_near = np.where(ca < lo, lo - ca, np.where(ca > hi, ca - hi, 0))
            d_far = np.maximum(np.abs(lo - ca), np.abs(hi - ca))
            near = near + weights[axis] * d_near * d_near
            far = far + weights[axis] * d_far * d_far
        r2 = int(r2)
        return (near <= r2) & (r2 <= far)
    k, rhs = _plane_coefficients(shape, box)
    rhs = rhs * 2**level  # compare sum k_a * i_a with D * den * 2**l
    assert rhs.denominator == 1
    fit = (sum(abs(x) for x in k) + 1) * 2 ** (level + 1) + abs(int(rhs))
    low = np.zeros(len(cells), dtype=object if fit >= 2**62 else np.int64)
    high = np.zeros_like(low)
    for axis in range(3):
        i = _exact_array(cells[:, axis], fit)
        a, b = k[axis] * i, k[axis] * (i + 1)
        low = low + np.minimum(a, b)
        high = high + np.maximum(a, b)
    rhs = int(rhs)
    return (low <= rhs) & (rhs <= high)


def _hits_bound(shape: Shape, box: Box, level: int) -> int:
    """An upper bound on the cells at ``level`` whose closed box meets the shape, without visiting them.

    A point meets at most 8 cells; a box exactly the product of its per-axis ranges; a
    plane, in the column of cells along its steepest axis, at most the cells an interval
    of its rise across one column meets.  A sphere's cells lie in the shell of one cell
    diagonal around it (a volume bound), and its surface, cut into six patches where one
    normal component is largest, rises at most one cell width per column (a column
    bound): the smaller of the two.  Only a size estimate is computed with floats here;
    which cells meet a shape is decided exactly by :func:`_meets`.
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
    if not _meets(shape, box, 0, np.zeros((1, 3), dtype=np.int64))[0]:
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
        hit = cells[_meets(shape, box, coarse, cells)]
        columns = len(np.unique(np.delete(hit, steep, axis=1), axis=0))
        return min(n**3, columns * 4 ** (level - coarse) * rise)
    sizes = [x / n for x in box.to_float()]
    diagonal = math.sqrt(sum(h * h for h in sizes))
    radius = float(shape.values[3])
    shell = 4 / 3 * math.pi * ((radius + diagonal) ** 3 - max(0.0, radius - diagonal) ** 3)
    columns = sum(2 * n * n * ((sizes[(a + 1) % 3] + sizes[(a + 2) % 3]) / sizes[a] + 2) for a in range(3))
    return min(n**3, math.ceil(min(shell / math.prod(sizes), columns)) + 1)


def estimate_leaves(box: Box, levels: int, shapes: Sequence[Shape]) -> int:
    """The leaves :func:`build_octree` would make, estimated in milliseconds from the shapes alone.

    Every split adds seven leaves; the cells split at a level are at most those meeting
    a shape there (:func:`_hits_bound`), and balancing adds about as many again as a
    fraction of them (measured: at most 1.3 times on spheres and planes).
    """
    split = sum(min(8**level, sum(_hits_bound(shape, box, level) for shape in shapes)) for level in range(levels))
    return 1 + 7 * split


# ---------------------------------------------------------------------------
# Keys and neighbourhoods


def distinct(keys: np.ndarray) -> np.ndarray:
    """The distinct values of an integer array, increasing.

    Sort and keep firsts: numpy's hash-based ``unique`` is much slower on int64 keys
    (4 million keys spread over 10**12: 5.5 s against 0.03 s CPU, numpy 2.4).
    """
    keys = np.sort(keys, axis=None)
    return keys[np.r_[True, keys[1:] != keys[:-1]]] if len(keys) else keys


def _keys_of(level: int, cells: np.ndarray) -> np.ndarray:
    """Linear keys of positions (n x 3) at ``level``."""
    n = np.int64(1 << level)
    cells = cells.astype(np.int64)
    return (cells[:, 0] * n + cells[:, 1]) * n + cells[:, 2]


def _cells_of(level: int, keys: np.ndarray) -> np.ndarray:
    """Positions (n x 3) of linear keys at ``level``."""
    n = np.int64(1 << level)
    keys = keys.astype(np.int64)
    return np.stack([keys // (n * n), (keys // n) % n, keys % n], axis=1)


def _offsets(balance: Balance) -> np.ndarray:
    """Neighbour offsets touching a cell across a face and an edge (``edge``), or also a corner (``vertex``)."""
    most = 3 if balance == "vertex" else 2
    return np.array([d for d in product((-1, 0, 1), repeat=3) if sum(map(abs, d)) <= most], dtype=np.int64)


def _neighbours(level: int, cells: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Positions of the cells (with the cells themselves) at ``offsets``, inside the domain, unique keys."""
    n = 1 << level
    near = (cells[:, None, :] + offsets[None, :, :]).reshape(-1, 3)
    near = near[np.all((near >= 0) & (near < n), axis=1)]
    return distinct(_keys_of(level, near))


def _children(level: int, keys: np.ndarray) -> np.ndarray:
    """Keys at ``level + 1`` of the eight children of cells at ``level``."""
    cells = _cells_of(level, keys) * 2
    kids = (cells[:, None, :] + np.array(list(product((0, 1), repeat=3)))[None]).reshape(-1, 3)
    return np.sort(_keys_of(level + 1, kids))


# ---------------------------------------------------------------------------
# The tree


@dataclass(frozen=True)
class Octree:
    """Leaves of a 1-irregular octree: ``levels`` (n,) and integer ``positions`` (n x 3), sorted by (level, key).

    ``depth`` is the finest leaf level.  Leaf ``i`` is the box
    ``positions[i] / 2**levels[i]`` (+ one cell) in unit coordinates of the domain.
    ``vertex_balanced``: known by construction to be leaves of a tree over the whole domain
    whose leaves touch across a face, an edge or a corner only when at most one level apart
    (:func:`build_octree` with ``balance="vertex"``): all of them, or a part (a device keeps
    the leaves inside its boxes); the exact Delaunay check then bounds
    where a vertex can lie near a leaf (:mod:`cospherical.mesh.checks`).  ``False``
    claims nothing.
    """

    box: Box
    levels: np.ndarray
    positions: np.ndarray
    vertex_balanced: bool = False

    @property
    def depth(self) -> int:
        return int(self.levels.max()) if len(self.levels) else 0

    def __len__(self) -> int:
        return len(self.levels)


def _leaves_from_splits(split: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Leaves of the tree whose split cells per level are ``split`` (level 0 is the root)."""
    levels, positions = [], []
    existing = np.zeros(1, dtype=np.int64)  # the root
    for level in range(len(split) + 1):
        here = split[level] if level < len(split) else np.zeros(0, dtype=np.int64)
        leaves = existing[~np.isin(existing, here, assume_unique=True)]
        levels.append(np.full(len(leaves), level, dtype=np.int8))
        positions.append(_cells_of(level, leaves))
        if level < len(split):
            existing = _children(level, here)
    return np.concatenate(levels), np.concatenate(positions)


def leaf_bound() -> int:
    """The most leaves a mesh may have on this machine: half its memory at :data:`BYTES_PER_LEAF` a leaf."""
    return max(1, machine_memory() // 2 // BYTES_PER_LEAF)


def check_leaf_count(count: int, what: str, max_leaves: int | None = None) -> None:
    """Refuse ``count`` leaves above ``max_leaves`` (default :func:`leaf_bound`), naming both."""
    bound = leaf_bound() if max_leaves is None else max_leaves
    if count > bound:
        raise InputError(f"{what} {count:,} leaves, above the bound of {bound:,} "
                         f"(half this machine's memory at {BYTES_PER_LEAF} bytes a leaf; --max-leaves N sets it)")


def build_octree(box: Box, levels: int, shapes: Sequence[Shape], balance: str = "vertex",
                 max_leaves: int | None = None,
                 must_split: Callable[[int, np.ndarray], np.ndarray] | None = None, resolve: int = 0,
                 name: str | None = None) -> Octree:
    """Refine every cell whose closed box meets a shape down to ``levels``, then 2:1 balance (coarsest).

    ``balance``: ``vertex`` (leaves touching across a face, an edge or a corner
    differ by at most one level; the default) or ``edge`` (faces and edges only).
    Face-only balance is refused: it is not 1-irregular (an edge can get two points).
    A tree whose estimated leaves (:func:`estimate_leaves`) exceed ``max_leaves``
    (default :func:`leaf_bound`) is refused before any cell is visited.
    ``must_split(level, cells)`` (cells n x 3 at ``level``): which cells are split
    whatever the shapes say, at every level below ``max(levels, resolve)`` (a device's
    region boundaries, :mod:`cospherical.mesh.device`).  A shape that does not meet the
    closed domain refines nothing: it is run without it, with a
    :class:`~cospherical.errors.CosphericalWarning` naming it (most likely a typo in a
    coordinate, or a shape meant for a domain of other lengths).

    Examples
    --------
    >>> tree = build_octree(Box.parse([1, 1, 1]), 2, [parse_shape("point:0.1,0.1,0.1")])
    >>> len(tree), sorted(set(tree.levels.tolist()))
    (15, [1, 2])
    >>> build_octree(Box.parse([1, 1, 1]), 2, [], balance="face")
    Traceback (most recent call last):
    ...
    cospherical.errors.InputError: --balance face: balance across faces alone is not 1-irregular (an edge can get two Steiner points); use edge or vertex
    """
    if balance == "face":
        raise InputError("--balance face: balance across faces alone is not 1-irregular "
                         "(an edge can get two Steiner points); use edge or vertex")
    known = next((kind for kind in BALANCES if kind == balance), None)
    if known is None:
        raise InputError(f"--balance {shown(balance)}: choose vertex or edge")
    if isinstance(levels, bool) or not isinstance(levels, int) or not 0 <= levels <= MAX_LEVEL:
        raise InputError(f"--levels {shown(levels)}: must be an integer from 0 to {MAX_LEVEL}")
    name = f"--levels {levels}" if name is None else name
    check_leaf_count(estimate_leaves(box, levels, shapes), f"{name}: an estimated", max_leaves)
    split: list[np.ndarray] = []
    existing = np.zeros(1, dtype=np.int64)
    deepest = max(levels, resolve)
    for level in range(deepest):
        cells = _cells_of(level, existing)
        hit = np.zeros(len(cells), dtype=bool)
        for shape in shapes if level < levels else ():
            meets = _meets(shape, box, level, cells)
            if level == 0 and not meets.any():  # the root cell is the whole closed domain
                warnings.warn(f"refine shape {shown(shape.text)} does not meet the domain: it refines nothing",
                              CosphericalWarning, stacklevel=2)
            hit |= meets
        if must_split is not None:
            hit |= must_split(level, cells)
        split.append(existing[hit])
        # every cell of the next level is or holds a leaf: the estimate's guard, before the children exist
        check_leaf_count(8 * len(split[-1]), f"{name}: level {level + 1} has at least", max_leaves)
        existing = _children(level, split[-1])
    offsets = _offsets(known)
    for level in range(deepest - 1, 0, -1):
        # every neighbour of a split cell must exist: its parent must be split
        need = _neighbours(level, _cells_of(level, split[level]), offsets)
        parents = distinct(_keys_of(level - 1, _cells_of(level, need) // 2))
        split[level - 1] = np.union1d(split[level - 1], parents)
    levels_, positions = _leaves_from_splits(split)
    check_leaf_count(len(levels_), f"{name}: balanced, the tree has", max_leaves)
    return Octree(box, levels_, positions, vertex_balanced=balance == "vertex")


# ---------------------------------------------------------------------------
# A tree brought as a list of leaves


def _leaf_integers(values, width: int, where: str, what: str) -> np.ndarray:
    """Levels (``width`` 1) or positions (rows of 3) as a flat int64 array, each an integer.

    numpy's own conversion to int64 truncates (a level 0.9 becomes 0, a position i + 0.5
    becomes i), reads a bool array as 0 and 1 and raises OverflowError past 64 bits: what
    numpy does not read as integers is looked at value by value, and the first that is not
    a plain integer of at most 64 bits raises InputError naming its leaf.
    """
    int64 = np.iinfo(np.int64)
    try:
        array = values if isinstance(values, np.ndarray) else np.asarray(values)
    except (ValueError, OverflowError, TypeError):  # rows of different lengths, ints past 64 bits
        array = None
    if array is not None and array.dtype.kind in "iu":
        flat = array.reshape(-1)
        if array.dtype.kind == "u" and array.dtype.itemsize == 8 and len(flat) and flat.max() > int64.max:
            bad = int(np.flatnonzero(flat > int64.max)[0])
            raise InputError(f"{where}: leaf {bad // width}: {what} {flat[bad]} is too large")
        flat = flat.astype(np.int64)
    else:
        try:
            flat = np.asarray(values, dtype=object).reshape(-1)
        except ValueError:
            raise InputError(f"{where}: the {what}s are not a list of integers") from None
        if width > 1 and flat.ndim == 1 and any(isinstance(value, (list, tuple, np.ndarray)) for value in flat):
            n = next(n for n, row in enumerate(flat) if not isinstance(row, (list, tuple, np.ndarray))
                     or len(row) != width)  # rows of different lengths: the first that is not 3 long
            raise InputError(f"{where}: leaf {n}: {what} {shown(flat[n])} is not {width} integers")
        for n, value in enumerate(flat):
            if not isinstance(value, (int, np.integer)) or isinstance(value, (bool, np.bool_)):
                value = value.item() if isinstance(value, np.generic) else value
                raise InputError(f"{where}: leaf {n // width}: {what} {shown(value)} is not an integer "
                                 f"(a {type(value).__name__})")
            if not int64.min <= value <= int64.max:
                raise InputError(f"{where}: leaf {n // width}: {what} {shown(int(value))} is too large")
        flat = flat.astype(np.int64)
    if len(flat) % width:
        raise InputError(f"{where}: {len(flat)} position numbers: not rows of 3")
    return flat


def leaves_octree(box: Box, levels: Sequence[int] | np.ndarray, positions: Sequence[Sequence[int]] | np.ndarray,
                  where: str = "leaves") -> Octree:
    """Check a list of leaves (level, i, j, k) and order it as an :class:`Octree`.

    The leaves must tile the domain (no overlap, no gap) and be 1-irregular (leaves
    touching across a face or an edge differ by at most one level); otherwise
    :class:`~cospherical.errors.InputError` names a bad leaf by its index in the list.

    Examples
    --------
    >>> tree = leaves_octree(Box.parse([1, 1, 1]), [0], [[0, 0, 0]])
    >>> len(tree), tree.depth
    (1, 0)
    >>> leaves_octree(Box.parse([1, 1, 1]), [1] * 7, [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0],
    ...                                               [0, 0, 1], [1, 0, 1], [0, 1, 1]])
    Traceback (most recent call last):
    ...
    cospherical.errors.InputError: leaves: no leaf covers the cell at level 1, position 1 1 1
    """
    levels = _leaf_integers(levels, 1, where, "level")
    positions = _leaf_integers(positions, 3, where, "position").reshape(-1, 3)
    if len(levels) == 0:
        raise InputError(f"{where}: no leaves")
    if len(levels) != len(positions):
        raise InputError(f"{where}: {len(levels)} levels but {len(positions)} positions")
    bad = np.flatnonzero((levels < 0) | (levels > MAX_LEVEL))
    if len(bad):
        raise InputError(f"{where}: leaf {bad[0]}: level {levels[bad[0]]} is not in 0..{MAX_LEVEL}")
    bad = np.flatnonzero(np.any((positions < 0) | (positions >= (1 << levels)[:, None]), axis=1))
    if len(bad):
        i = bad[0]
        raise InputError(f"{where}: leaf {i}: position {' '.join(map(str, positions[i]))} is outside the domain "
                         f"at level {levels[i]} (0..{(1 << levels[i]) - 1})")
    depth = int(levels.max())
    keys = {level: _keys_of(level, positions[levels == level]) for level in range(depth + 1)}
    index = {level: np.flatnonzero(levels == level) for level in range(depth + 1)}
    for level in range(depth + 1):
        order = np.argsort(keys[level], kind="stable")
        k = keys[level][order]
        same = np.flatnonzero(k[1:] == k[:-1])
        if len(same):
            a, b = sorted(index[level][order[same[0]:same[0] + 2]])
            raise InputError(f"{where}: leaf {b} repeats leaf {a} (level {level}, position "
                             f"{' '.join(map(str, positions[a]))})")
    # split[l]: the cells of level l that are ancestors of a leaf; a leaf must not be one
    split = []
    for level in range(depth):
        deeper = [_keys_of(level, _cells_of(d, keys[d]) >> (d - level)) for d in range(level + 1, depth + 1)]
        split.append(distinct(np.concatenate(deeper)) if deeper else np.zeros(0, dtype=np.int64))
        clash = np.isin(keys[level], split[level])
        if clash.any():
            i = index[level][np.flatnonzero(clash)[0]]
            raise InputError(f"{where}: leaf {i} (level {level}, position {' '.join(map(str, positions[i]))}) "
                             "overlaps smaller leaves inside it")
    # no gap: every child of a split cell exists (is a leaf or split)
    existing = np.zeros(1, dtype=np.int64)
    for level in range(depth + 1):
        here = np.union1d(keys[level], split[level] if level < depth else np.zeros(0, dtype=np.int64))
        missing = existing[~np.isin(existing, here)]
        if len(missing):
            cell = _cells_of(level, missing[:1])[0]
            raise InputError(f"{where}: no leaf covers the cell at level {level}, position "
                             f"{' '.join(map(str, cell))}")
        if level < depth:
            existing = _children(level, split[level])
    # 1-irregular: every face or edge neighbour of a split cell exists
    offsets = _offsets("edge")
    for level in range(1, depth):
        need = _neighbours(level, _cells_of(level, split[level]), offsets)
        parents = _keys_of(level - 1, _cells_of(level, need) // 2)
        lacking = np.flatnonzero(~np.isin(parents, split[level - 1]))
        if len(lacking):
            cell = _cells_of(level, need[lacking[:1]])[0]
            # the leaf holding that cell is coarser than its parent: find it by its ancestors
            for coarse in range(level - 1, -1, -1):
                key = _keys_of(coarse, (cell >> (level - coarse))[None])[0]
                hit = np.flatnonzero(keys[coarse] == key)
                if len(hit):
                    i = index[coarse][hit[0]]
                    raise InputError(f"{where}: leaf {i} (level {coarse}, position "
                                     f"{' '.join(map(str, positions[i]))}) touches leaves of level {level + 1} "
                                     "across a face or an edge: not 1-irregular (2:1 balance)")
    levels_, positions_ = _leaves_from_splits(split)
    return Octree(box, levels_, positions_)


def leaf_list_order(levels: Sequence[int] | np.ndarray, positions: Sequence[Sequence[int]] | np.ndarray) -> np.ndarray:
    """For each leaf of ``leaves_octree(box, levels, positions)``, in the tree's order, its index in the list.

    The tree sorts its leaves by (level, key); a list that :func:`leaves_octree`
    accepted holds each leaf once, so sorting the list the same way pairs them.

    Examples
    --------
    >>> levels, positions = [1] * 8, [[i >> 2, (i >> 1) & 1, i & 1] for i in range(8)][::-1]
    >>> tree = leaves_octree(Box.parse([1, 1, 1]), levels, positions)
    >>> order = leaf_list_order(levels, positions)
    >>> order.tolist(), [positions[i] for i in order] == tree.positions.tolist()
    ([7, 6, 5, 4, 3, 2, 1, 0], True)
    """
    levels = np.asarray(levels, dtype=np.int64).reshape(-1)
    positions = np.asarray(positions, dtype=np.int64).reshape(-1, 3)
    keys = np.zeros(len(levels), dtype=np.int64)
    for level in np.unique(levels).tolist():
        at = levels == level
        keys[at] = _keys_of(level, positions[at])
    return np.lexsort((keys, levels))
