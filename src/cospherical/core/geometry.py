"""Exact predicates on an integer frame.

A point (s*a, t*b, u*c) of the box is stored as integers (S, T, U) = D*(s, t, u)
with D the common denominator of all unit coordinates, and the squared box
lengths as integer weights (wa, wb, wc) proportional to (a^2, b^2, c^2).
The map (S, T, U) -> real point is a positive diagonal scaling, so planes,
orientations, convexity and volume ratios are the same in both frames.
Distances are not; they enter only through the lifted coordinate
L = wa*S^2 + wb*T^2 + wc*U^2, which is a positive multiple of |x|^2.  A sphere
through real points is a hyperplane through their lifted images, so
co-sphericity and in-sphere tests are integer determinants.  Every decision in
the project (coplanar, co-spherical, inside, right angle) is made here, with
Python integers: no tolerance anywhere.
"""

from __future__ import annotations

import math
import operator
from dataclasses import dataclass
from fractions import Fraction
from typing import Mapping, Sequence

__all__ = ["Frame", "Sphere", "cross", "dot", "six_volume", "sphere_sides", "sub", "tetra_six_volume"]

Vector = tuple[int, int, int]


# map over operator functions, not generators: these run in the inner loops of the
# Delaunay walk and the split search (about three times faster).
def sub(p: Sequence[int], q: Sequence[int]) -> tuple[int, ...]:
    return tuple(map(operator.sub, p, q))


def dot(p: Sequence[int], q: Sequence[int]) -> int:
    return sum(map(operator.mul, p, q))


def cross(p: Sequence[int], q: Sequence[int]) -> Vector:
    return (p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0])


def tetra_six_volume(p: Sequence, q: Sequence, r: Sequence, s: Sequence):
    """Six times the signed volume of the tetrahedron pqrs (zero: the four are coplanar), exact for
    integers and Fractions alike."""
    return dot(sub(q, p), cross(sub(r, p), sub(s, p)))


def sphere_sides(tets, points, weights: Sequence[int]):
    """Per row, where a point lies against a tetrahedron's circumsphere, in bulk: < 0 strictly inside, 0 on, > 0 outside.

    ``tets``: integer array (n, 4, 3) of solid tetrahedra, either orientation;
    ``points``: (n, 3); ``weights``: the frame's.  With d_k the edges from the first
    vertex, e the point from it and L the lifted length (weights . x^2), the centre
    c solves 2 W c . d_k = L(d_k), so W c = N / (2 det) by Cramer's rule
    (N: the three determinants with one column replaced by L), and e is inside
    exactly when L(e) < e . N / det.  numpy's int64 when the bound fits, else Python
    integers (object arrays): exact either way.

    >>> import numpy as np
    >>> cube = np.array([[[0, 0, 0], [2, 0, 0], [0, 2, 0], [0, 0, 2]]] * 3)
    >>> sphere_sides(cube, np.array([[1, 1, 1], [2, 2, 2], [3, 0, 0]]), (1, 1, 1)).tolist()
    [-1, 0, 1]
    """
    import numpy as np

    tets, points = np.asarray(tets, dtype=np.int64), np.asarray(points, dtype=np.int64)
    d = tets[:, 1:] - tets[:, :1]
    e = points - tets[:, 0]
    extent = max(int(np.abs(d).max(initial=0)), int(np.abs(e).max(initial=0)), 1)
    # |det| <= 6 E^3 and |lifted| <= 3 w E^2, so |det * L(e)| <= 18 w E^5 and |towards| <= 3 * 18 w E^5:
    # every term and the side itself stay below 72 w E^5
    if 72 * max(weights) * extent ** 5 >= 2 ** 63:
        d, e = d.astype(object), e.astype(object)
        w = np.array([int(x) for x in weights], dtype=object)
    else:
        w = np.array(weights, dtype=np.int64)
    lifted = (d * d * w).sum(axis=2)
    det = np.einsum("ij,ij->i", d[:, 0], np.cross(d[:, 1], d[:, 2]))
    towards = 0
    for axis in range(3):
        m = d.copy()
        m[:, :, axis] = lifted
        towards = towards + e[:, axis] * np.einsum("ij,ij->i", m[:, 0], np.cross(m[:, 1], m[:, 2]))
    side = (det * (e * e * w).sum(axis=1) - towards) * np.where(det < 0, -1, 1)
    return np.sign(side).astype(np.int8)


def six_volume(coords, cycles) -> int:
    """Six times the volume of a polyhedron from its face cycles (indices into ``coords``).

    With the cycles counter-clockwise seen from outside every fan tetrahedron
    from a vertex is right-handed or flat, so the sum is positive; reversed
    cycles (a mirror image's faces) give the negative.
    """
    ax, ay, az = coords[cycles[0][0]]
    total = 0
    for cycle in cycles:
        x0, y0, z0 = coords[cycle[0]]
        px, py, pz = x0 - ax, y0 - ay, z0 - az
        for a, b in zip(cycle[1:-1], cycle[2:]):
            (x1, y1, z1), (x2, y2, z2) = coords[a], coords[b]
            ux, uy, uz, vx, vy, vz = x1 - ax, y1 - ay, z1 - az, x2 - ax, y2 - ay, z2 - az
            total += px * (uy * vz - uz * vy) + py * (uz * vx - ux * vz) + pz * (ux * vy - uy * vx)
    return total


def _det3(r0, r1, r2) -> int:
    return dot(r0, cross(r1, r2))


@dataclass(frozen=True)
class Sphere:
    """The sphere through four lifted points, as the hyperplane ``normal . x = offset``.

    ``normal[3] > 0`` always, so ``side(x) < 0`` exactly when x is strictly inside.
    """

    normal: tuple[int, int, int, int]
    offset: int

    def side(self, lifted_point: Sequence[int]) -> int:
        """Negative inside, zero on the sphere, positive outside (scaled, exact)."""
        a, b, c, d = self.normal
        x, y, z, w = lifted_point
        return a * x + b * y + c * z + d * w - self.offset


@dataclass(frozen=True)
class Frame:
    """Integer coordinates of a point set in a box, with exact predicates."""

    ids: tuple[int, ...]
    coords: tuple[Vector, ...]
    lifted: tuple[tuple[int, int, int, int], ...]
    scale: int
    weights: Vector

    @classmethod
    def build(cls, unit_points: Mapping[int, Sequence[Fraction]], squared_lengths: Sequence[Fraction]) -> "Frame":
        """Frame for ``{node id: unit coordinates}`` in a box with the given squared lengths."""
        ids = tuple(sorted(unit_points))
        # Integer arithmetic on numerators and denominators: a mesher calls this per configuration.
        points = [[x if isinstance(x, (int, Fraction)) else Fraction(x) for x in unit_points[i]] for i in ids]
        scale = math.lcm(*(x.denominator for point in points for x in point))
        squared = [w if isinstance(w, (int, Fraction)) else Fraction(w) for w in squared_lengths]
        weight_den = math.lcm(*(w.denominator for w in squared))
        weights = tuple(w.numerator * (weight_den // w.denominator) for w in squared)
        coords = tuple(tuple(x.numerator * (scale // x.denominator) for x in point) for point in points)
        lifted = tuple((*p, weights[0] * p[0] ** 2 + weights[1] * p[1] ** 2 + weights[2] * p[2] ** 2) for p in coords)
        return cls(ids, coords, lifted, scale, weights)

    def orient(self, i: int, j: int, k: int, m: int) -> int:
        """Sign-bearing 6x volume of (i, j, k, m), indices into ``coords``; > 0 when right-handed."""
        p = self.coords[i]
        return _det3(sub(self.coords[j], p), sub(self.coords[k], p), sub(self.coords[m], p))

    def sphere(self, i: int, j: int, k: int, m: int) -> Sphere | None:
        """The sphere through four points, or ``None`` if they are coplanar."""
        b0, b1, b2, b3 = self.lifted[i]
        (x1, y1, z1, w1), (x2, y2, z2, w2), (x3, y3, z3, w3) = (
            (p[0] - b0, p[1] - b1, p[2] - b2, p[3] - b3) for p in (self.lifted[j], self.lifted[k], self.lifted[m])
        )
        # Cofactors of the 4x4 determinant [rows; v] along v: normal . v = det.
        # 2x2 minors of the first two rows, shared by the four 3x3 minors.
        xy, xz, xw = x1 * y2 - x2 * y1, x1 * z2 - x2 * z1, x1 * w2 - x2 * w1
        yz, yw, zw = y1 * z2 - y2 * z1, y1 * w2 - y2 * w1, z1 * w2 - z2 * w1
        normal = (
            -(y3 * zw - z3 * yw + w3 * yz),
            x3 * zw - z3 * xw + w3 * xz,
            -(x3 * yw - y3 * xw + w3 * xy),
            x3 * yz - y3 * xz + z3 * xy,
        )
        if normal[3] == 0:
            return None
        if normal[3] < 0:
            normal = (-normal[0], -normal[1], -normal[2], -normal[3])
        return Sphere(normal, normal[0] * b0 + normal[1] * b1 + normal[2] * b2 + normal[3] * b3)

    def center(self, sphere: Sphere) -> tuple[Fraction, Fraction, Fraction]:
        """Exact unit coordinates of a sphere's center."""
        n = sphere.normal
        return tuple(Fraction(-n[axis], 2 * self.weights[axis] * n[3] * self.scale) for axis in range(3))

    def real_dot(self, u: Sequence[int], v: Sequence[int]) -> int:
        """A positive multiple of the real dot product of two frame vectors."""
        return sum(w * x * y for w, x, y in zip(self.weights, u, v))
