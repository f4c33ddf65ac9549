"""Exact thresholds along a ray of boxes, such as (1, r, r) or (1, 1, r).

Along a ray the squared lengths are w0 + u*w1 with u = r^2.  Every quantity
that decides a tessellation is then linear in u: an in-sphere determinant has
one column (the lifted one, L0 + u*L1) that depends on u; a circumcenter
coordinate compared with a box face is a linear form; a right angle is a dot
product weighted by the squared lengths.  So a tessellation computed at one
value of u stays the Delaunay subdivision, with the same FVM verdict and the
same face kinds, on the open interval between the nearest roots of those
linear forms: exact rationals.  Sweeping u interval by interval gives every
value where something can change, exactly; a threshold is reported where the
FVM count or the set of element types really changes, as r = sqrt(u).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any
from fractions import Fraction

from ..caches import cached
from ..core.configuration import Box, Configuration
from ..core.exact import Length
from ..core.geometry import Frame, sub
from ..core.symmetry import box_symmetries, orbit_representatives
from ..core.tessellation import tessellate
from ..errors import InputError
from .engine import bisection_codes

__all__ = ["Ray", "Step", "code_pieces", "profile_summary", "ray_profile"]

# A configuration's state at a box of the ray: FVM-adequate or not, and its element types.
State = tuple[bool, frozenset[str]]


@dataclass(frozen=True)
class Ray:
    """Box (a, b, c) with each length 1 or r; ``scaled[i]`` says which."""

    scaled: tuple[bool, bool, bool]

    @classmethod
    def parse(cls, text: str) -> "Ray":
        parts = [p.strip().lower() for p in text.split(",")]
        if len(parts) != 3 or any(p not in ("1", "r") for p in parts) or "r" not in parts:
            raise InputError(f"ray {text!r}: write three lengths, each 1 or r, for example 1,r,r")
        a, b, c = (p == "r" for p in parts)
        return cls((a, b, c))

    @property
    def text(self) -> str:
        return ",".join("r" if s else "1" for s in self.scaled)

    def box(self, u: Fraction) -> Box:
        return Box(*(Length(u if s else Fraction(1)) for s in self.scaled))

    @property
    def w0(self) -> tuple[int, int, int]:
        a, b, c = (0 if s else 1 for s in self.scaled)
        return (a, b, c)

    @property
    def w1(self) -> tuple[int, int, int]:
        a, b, c = (1 if s else 0 for s in self.scaled)
        return (a, b, c)


class _Critical(Exception):
    """The probed value of u is itself a root: probe elsewhere."""


def _linear_forms(code: str, ray: Ray, u: Fraction) -> tuple[list[tuple[int, int]], State]:
    """The linear forms a + b*u whose signs hold the tessellation at u, and its state there.

    Raises :class:`_Critical` when u is a root of one of them (a degenerate value).
    """
    cfg = Configuration.from_code(code, ray.box(u))
    tess = tessellate(cfg)
    f0 = Frame.build(tess.nodes, ray.w0)
    f1 = Frame.build(tess.nodes, ray.w1)
    index = {node: i for i, node in enumerate(f0.ids)}
    forms: list[tuple[int, int]] = []
    for element in tess.elements:
        members = [index[n] for n in element.polyhedron.nodes]
        quad = f0.spanning(members)
        assert quad is not None, "a Delaunay element is solid"
        s0, s1 = f0.sphere(*quad), f1.sphere(*quad)
        assert s0 is not None and s1 is not None, "four points that span a solid lie on one sphere"
        for x in range(len(f0.ids)):
            a, b = s0.side(f0.lifted[x]), s1.side(f1.lifted[x])
            if x in members:
                if a or b:  # co-spherical only at this u
                    raise _Critical
            else:
                forms.append((a, b))
        # circumcenter between the box faces: 0 <= -N_axis(u) <= 2 w_axis(u) N_L D
        n_l = s0.normal[3]
        for axis in range(3):
            n0, n1 = s0.normal[axis], s1.normal[axis]
            forms.append((-n0, -n1))
            forms.append((2 * ray.w0[axis] * n_l * f0.scale + n0, 2 * ray.w1[axis] * n_l * f0.scale + n1))
        # right angles of four-sided faces
        for face in element.polyhedron.faces:
            if len(face) == 4:
                pts = [f0.coords[index[n]] for n in face]  # f1's too: the frames differ in their weights alone
                for i in range(4):
                    e, e2 = sub(pts[(i + 1) % 4], pts[i]), sub(pts[(i + 2) % 4], pts[(i + 1) % 4])
                    forms.append((f0.real_dot(e, e2), f1.real_dot(e, e2)))
    p, q = u.numerator, u.denominator
    for a, b in forms:
        if b and -a * q == p * b:  # the root -a/b is u (integers: no Fraction per form)
            raise _Critical
    state = (tess.fvm_adequate, frozenset(e.type.id for e in tess.elements))
    return forms, state


def _interval(forms: Iterable[tuple[int, int]], u: Fraction) -> tuple[Fraction | None, Fraction | None]:
    """The nearest roots -a/b of the forms below and above u (None: no root on that side).

    Roots are compared as integer cross-products, each root ``n / d`` with ``d > 0``: a study's
    configuration has thousands of forms, and a Fraction per form cost most of a ray's profile.
    """
    p, q = u.numerator, u.denominator
    lo: tuple[int, int] | None = None
    hi: tuple[int, int] | None = None
    for a, b in set(forms):
        if b:
            n, d = (-a, b) if b > 0 else (a, -b)
            if n * q < p * d:
                if lo is None or n * lo[1] > lo[0] * d:
                    lo = (n, d)
            elif n * q > p * d and (hi is None or n * hi[1] < hi[0] * d):
                hi = (n, d)
    return (None if lo is None else Fraction(*lo)), (None if hi is None else Fraction(*hi))


def _state_at(code: str, ray: Ray, u: Fraction) -> State:
    tess = tessellate(Configuration.from_code(code, ray.box(u)))
    return tess.fvm_adequate, frozenset(e.type.id for e in tess.elements)


@cached(maxsize=1 << 14)
def code_pieces(code: str, ray: Ray, u_lo: Fraction, u_hi: Fraction) -> tuple[tuple[Fraction, Fraction, State], ...]:
    """The configuration's state on [u_lo, u_hi] as pieces ``(u_from, u_to, state)``.

    Open intervals alternate with single points (``u_from == u_to``), starting
    and ending with the points u_lo and u_hi; a state is (fvm_adequate, types).
    """
    pieces = [(u_lo, u_lo, _state_at(code, ray, u_lo))]
    pos = u_lo
    while pos < u_hi:
        probe = (pos + u_hi) / 2
        while True:
            try:
                forms, state = _linear_forms(code, ray, probe)
            except _Critical:
                probe = (pos + probe) / 2
                continue
            lo, hi = _interval(forms, probe)
            if lo is not None and lo > pos:
                probe = (pos + lo) / 2  # another critical value lies between pos and lo
                continue
            break
        end = u_hi if hi is None or hi > u_hi else hi
        pieces.append((pos, end, state))
        pieces.append((end, end, _state_at(code, ray, end)))
        pos = end
    return tuple(pieces)


@dataclass(frozen=True)
class Step:
    """The study's state for u = r^2 from ``lo`` to ``hi`` (each end in or out as the flags say)."""

    lo: Fraction
    hi: Fraction
    lo_closed: bool
    hi_closed: bool
    fvm_adequate: int
    types: frozenset[str]

    def contains(self, u: Fraction) -> bool:
        return (self.lo < u or (self.lo_closed and u == self.lo)) and (u < self.hi or (self.hi_closed and u == self.hi))

    def describe(self) -> str:
        """``[sqrt(2), 2)`` in r."""
        lo, hi = Length(self.lo).text, Length(self.hi).text
        if self.lo == self.hi:
            return f"r = {lo}"
        return f"{'[' if self.lo_closed else '('}{lo}, {hi}{']' if self.hi_closed else ')'}"


def ray_profile(ray: Ray, r_lo: Fraction, r_hi: Fraction,
                progress: Callable[[int], None] | None = None) -> list[Step]:
    """The bisection study along the ray for r in [r_lo, r_hi], exactly, as steps in u = r^2."""
    u_lo, u_hi = r_lo * r_lo, r_hi * r_hi
    codes = bisection_codes()
    # symmetries common to every box of the ray (those of a generic member)
    generic = ray.box((u_lo + u_hi) / 2 if u_lo != u_hi else u_lo + 1)
    reps, _ = orbit_representatives(codes, box_symmetries(generic))
    sizes = Counter(reps)
    per_code = {}
    for rep in sorted(sizes):
        per_code[rep] = code_pieces(rep, ray, u_lo, u_hi)
        if progress:
            progress(sizes[rep])
    cuts = sorted({p[0] for pieces in per_code.values() for p in pieces})
    spans = []
    for i, cut in enumerate(cuts):
        spans.append((cut, cut, cut))
        if i + 1 < len(cuts):
            spans.append((cut, cuts[i + 1], (cut + cuts[i + 1]) / 2))
    steps = []
    for u_from, u_to, probe in spans:
        fvm = 0
        types: set[str] = set()
        for rep, pieces in per_code.items():
            state = _state_in(pieces, probe)
            fvm += sizes[rep] * state[0]
            types |= state[1]
        point = u_from == u_to
        steps.append(Step(u_from, u_to, point, point, fvm, frozenset(types)))
    merged = [steps[0]]
    for step in steps[1:]:
        last = merged[-1]
        if (step.fvm_adequate, step.types) == (last.fvm_adequate, last.types):
            merged[-1] = Step(last.lo, step.hi, last.lo_closed, step.hi_closed, last.fvm_adequate, last.types)
        else:
            merged.append(step)
    return merged


def _state_in(pieces: Iterable[tuple[Fraction, Fraction, State]], u: Fraction) -> State:
    """The state at u: of the point piece at u, else of the open interval around u."""
    for start, end, state in pieces:
        if start == end == u or start < u < end:
            return state
    raise ValueError(f"u = {u} is outside the pieces")


def profile_summary(ray: Ray, r_lo: Fraction, r_hi: Fraction, steps: list[Step]) -> dict[str, Any]:
    """The JSON shape of ``cospherical sweep --ray``: steps in r, thresholds, largest fully adequate r."""
    def text(u: Fraction) -> str:
        return Length(u).text

    rows = [
        {"r_from": text(s.lo), "r_to": text(s.hi), "from_closed": s.lo_closed, "to_closed": s.hi_closed,
         "u_from": str(s.lo), "u_to": str(s.hi), "fvm_adequate": s.fvm_adequate, "types": len(s.types)}
        for s in steps
    ]
    thresholds = sorted({s.lo for s in steps[1:]} | {s.hi for s in steps[:-1]})
    largest = None
    for step in steps:
        if step.fvm_adequate != 4096:
            break
        largest = {"r": text(step.hi), "attained": step.hi_closed}
    return {
        "ray": ray.text,
        "range": [Length(r_lo * r_lo).text, Length(r_hi * r_hi).text],
        "steps": rows,
        "thresholds": [{"r": text(u), "u": str(u)} for u in thresholds],
        "largest_fully_adequate": largest,
    }
