"""The exact geometry kernel: every predicate and construction of the project, on an integer frame.

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

Python integers (and ``Fraction``s where a caller has them) in the scalar
functions and the :class:`Frame`: they never overflow.  The bulk functions on
numpy arrays (:func:`six_volumes`, :func:`sphere_sides`, :func:`circumcenters`)
choose their backend themselves, by a bound derived in their comments: numpy's
int64 when every term provably stays below 2**62 or 2**63, else object arrays
of Python integers; the same numbers either way (``python_integers=True`` takes
Python integers regardless: tests compare the two).  The compiled walk
(:mod:`cospherical.core.compiled`, numba, int64) is chosen only by its caller's
explicit ``backend="compiled"`` and checks its own bound
(:func:`cospherical.core.compiled.fits`).

The module is in two parts, as a geometry kernel's traits are: predicates
(signs: orientation, collinearity, side of a sphere) and constructions (exact
numbers: vectors, normals, determinants, volumes, spheres, circumcentres).
Code elsewhere asks these and computes no determinant of its own.
"""

from __future__ import annotations

import math
import operator
from dataclasses import dataclass
from fractions import Fraction
from itertools import combinations
from typing import TYPE_CHECKING, Any, Mapping, Sequence, TypeVar, cast

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import NDArray

__all__ = ["Frame", "Rational", "Sphere", "area_vector", "circumcenters", "collinear", "cross", "determinant", "dot",
           "in_closed_box", "plane_normal", "plane_projection", "six_volume", "six_volumes", "sphere_sides", "sub", "tetra_six_volume"]

_Vector = tuple[int, int, int]
Rational = int | Fraction
"""An exact scalar: the kernel's functions take integers and Fractions alike."""
# Integers in, integers out; Fractions in, Fractions out; either kind mixed: either kind out.
_R = TypeVar("_R", int, Fraction, Rational)
# The integer 0 starts a sum of either kind (typed Any: a Fraction sum starts from it too).
_ZERO: Any = 0


# ---------------------------------------------------------------------------------------------
# Predicates: signs, decided exactly
# ---------------------------------------------------------------------------------------------

def tetra_six_volume(p: Sequence[_R], q: Sequence[_R], r: Sequence[_R], s: Sequence[_R]) -> _R:
    """Six times the signed volume of the tetrahedron pqrs (zero: the four are coplanar), exact for
    integers and Fractions alike: the orientation predicate (> 0 when right-handed)."""
    return determinant(sub(q, p), sub(r, p), sub(s, p))


def collinear(p: Sequence[_R], q: Sequence[_R], r: Sequence[_R]) -> bool:
    """Whether the three points are on one line (or two of them coincide)."""
    return not any(plane_normal(p, q, r))


def sphere_sides(tets: NDArray[Any], points: NDArray[Any], weights: Sequence[int],
                 python_integers: bool = False) -> NDArray[np.int8]:
    """Per row, where a point lies against a tetrahedron's circumsphere, in bulk: < 0 strictly inside, 0 on, > 0 outside.

    ``tets``: integer array (n, 4, 3) of solid tetrahedra, either orientation;
    ``points``: (n, 3); ``weights``: the frame's.  With d_k the edges from the first
    vertex, e the point from it and L the lifted length (weights . x^2), the centre
    c solves 2 W c . d_k = L(d_k), so W c = N / (2 det) by Cramer's rule
    (N: the three determinants with one column replaced by L, :func:`_cramer`), and
    e is inside exactly when L(e) < e . N / det.  numpy's int64 when the bound fits,
    else (or with ``python_integers``) Python integers (object arrays): exact either way.

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
    if python_integers or 72 * max(weights) * extent ** 5 >= 2 ** 63:
        d, e = d.astype(object), e.astype(object)
        w = np.array([int(x) for x in weights], dtype=object)
    else:
        w = np.array(weights, dtype=np.int64)
    det, numerators = _cramer(d, w)
    towards = 0
    for axis in range(3):
        towards = towards + e[:, axis] * numerators[axis]
    side = (det * (e * e * w).sum(axis=1) - towards) * np.where(det < 0, -1, 1)
    signs: NDArray[np.int8] = np.sign(side).astype(np.int8)
    return signs


def in_closed_box(numerators: NDArray[Any], denominators: NDArray[Any], low: int | NDArray[Any],
                  high: int | NDArray[Any]) -> NDArray[np.bool_]:
    """Per row of rational points ``numerators / denominators`` (n, 3), in bulk, whether it lies in the
    closed box ``low``..``high`` (broadcast per row or per axis; denominators positive): each numerator
    against the bounds times its denominator, in the arrays' own integers (the caller's bound makes
    int64 exact, else it passes Python integers).

    >>> import numpy as np
    >>> in_closed_box(np.array([[1, 2, 3], [1, 2, 7]]), np.array([[2], [2]]), 0, 3).tolist()
    [True, False]
    """
    inside = (numerators >= low * denominators) & (numerators <= high * denominators)
    return cast("NDArray[np.bool_]", inside.all(axis=1))


# ---------------------------------------------------------------------------------------------
# Constructions: exact numbers
# ---------------------------------------------------------------------------------------------

# map over operator functions, not generators: these run in the inner loops of the
# Delaunay walk and the split search (about three times faster).
def sub(p: Sequence[_R], q: Sequence[_R]) -> tuple[_R, ...]:
    return tuple(map(operator.sub, p, q))


def dot(p: Sequence[_R], q: Sequence[_R]) -> _R:
    total: _R = sum(map(operator.mul, p, q))
    return total


def cross(p: Sequence[_R], q: Sequence[_R]) -> tuple[_R, _R, _R]:
    return (p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0])


def determinant(u: Sequence[_R], v: Sequence[_R], w: Sequence[_R]) -> _R:
    """The determinant of the rows u, v, w (the triple product u . (v x w)), written out: it runs in
    the inner loops of the dual's pieces and the hull's face order."""
    return (u[0] * (v[1] * w[2] - v[2] * w[1]) + u[1] * (v[2] * w[0] - v[0] * w[2])
            + u[2] * (v[0] * w[1] - v[1] * w[0]))


def plane_normal(p: Sequence[_R], q: Sequence[_R], r: Sequence[_R]) -> tuple[_R, _R, _R]:
    """(q - p) x (r - p): normal to the plane of p, q, r, right-handed (zero when they are on a line),
    written out: it runs once per point triple of every hull."""
    (x0, y0, z0), (x1, y1, z1), (x2, y2, z2) = p, q, r
    ux, uy, uz, vx, vy, vz = x1 - x0, y1 - y0, z1 - z0, x2 - x0, y2 - y0, z2 - z0
    return (uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx)


def area_vector(polygon: Sequence[Sequence[_R]]) -> tuple[_R, _R, _R]:
    """Twice the vector area of a closed polygon (Newell's normal): for a planar polygon, normal to
    its plane, right-handed around its order; never zero for a convex one, even with three
    consecutive points on a line (a normal from three points would be).

    >>> area_vector([(0, 0, 0), (1, 0, 0), (2, 0, 0), (2, 1, 0), (0, 1, 0)])
    (0, 0, 4)
    """
    m = len(polygon)
    normal: tuple[_R, _R, _R] = (_ZERO, _ZERO, _ZERO)
    for i in range(m):
        p, q = polygon[i], polygon[(i + 1) % m]
        normal = (normal[0] + (p[1] - q[1]) * (p[2] + q[2]), normal[1] + (p[2] - q[2]) * (p[0] + q[0]),
                  normal[2] + (p[0] - q[0]) * (p[1] + q[1]))
    return normal


def plane_projection(point: Sequence[int], origin: Sequence[int], normal: Sequence[int],
                     inverse_weights: Sequence[int]) -> tuple[tuple[int, ...], int]:
    """The projection of ``point`` onto the plane through ``origin`` with ``normal`` (frame coordinates),
    orthogonal in the real metric: ``inverse_weights`` proportional to the inverse weights (integers,
    lcm(w) // w_k).  Returns ``(numerators, s)``, the projection being numerators / s with
    s = sum N_k^2 / w_k (scaled as the inverse weights): along the real normal, W^-1 N.

    >>> plane_projection((3, 4, 5), (0, 0, 1), (0, 0, 1), (1, 1, 1))
    ((3, 4, 1), 1)
    """
    s = sum(n * n * v for n, v in zip(normal, inverse_weights))
    along = dot(sub(point, origin), normal)
    return tuple(x * s - along * n * v for x, n, v in zip(point, normal, inverse_weights)), s


def six_volume(coords: Sequence[Sequence[_R]], cycles: Sequence[Sequence[int]]) -> _R:
    """Six times the volume of a polyhedron from its face cycles (indices into ``coords``).

    With the cycles counter-clockwise seen from outside every fan tetrahedron
    from a vertex is right-handed or flat, so the sum is positive; reversed
    cycles (a mirror image's faces) give the negative.
    """
    ax, ay, az = coords[cycles[0][0]]
    total: _R = _ZERO
    for cycle in cycles:
        x0, y0, z0 = coords[cycle[0]]
        px, py, pz = x0 - ax, y0 - ay, z0 - az
        for a, b in zip(cycle[1:-1], cycle[2:]):
            (x1, y1, z1), (x2, y2, z2) = coords[a], coords[b]
            ux, uy, uz, vx, vy, vz = x1 - ax, y1 - ay, z1 - az, x2 - ax, y2 - ay, z2 - az
            total += px * (uy * vz - uz * vy) + py * (uz * vx - ux * vz) + pz * (ux * vy - uy * vx)
    return total


def six_volumes(tets: NDArray[Any], python_integers: bool = False) -> NDArray[Any]:
    """Per tetrahedron of an integer array (n, 4, 3), six times its signed volume, in bulk (0: flat).

    int64 when |6 E^3| < 2**62 (E the largest edge component from the first vertex: each
    triple-product term is at most 2 E^3), else (or with ``python_integers``) Python integers (an
    object array).

    >>> import numpy as np
    >>> six_volumes(np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], [[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 0, 1]]])).tolist()
    [1, 0]
    """
    import numpy as np

    tets = np.asarray(tets, dtype=np.int64)
    d = tets[:, 1:] - tets[:, :1]
    extent = int(np.abs(d).max()) if len(d) else 0
    if python_integers or 6 * extent ** 3 >= 2**62:
        d = d.astype(object)
    volumes: NDArray[Any] = np.einsum("ij,ij->i", d[:, 0], np.cross(d[:, 1], d[:, 2]))
    return volumes


def circumcenters(tets: NDArray[Any], weights: Sequence[int],
                  python_integers: bool = False) -> tuple[NDArray[Any], NDArray[Any]]:
    """Per tetrahedron of an integer array (n, 4, 3), its exact circumcentre in the same units, in bulk:
    ``(numerators, denominators)``, each (n, 3), every coordinate a reduced fraction with a positive
    denominator (the tetrahedra solid; ``weights``: the frame's, as in :func:`sphere_sides`).

    The centre is p0 + N / (2 W det) per axis (:func:`_cramer`).  With E the largest edge
    component from p0 and C the largest coordinate: |2 w det| <= 12 w E^3 and |N| <= 18 w E^4, so
    the numerator p0 2 w det + N stays below 24 w E^3 (C + E + 1); int64 when that is below
    2**62, else (or with ``python_integers``) Python integers (object arrays; the weights of extreme
    boxes, 1e-12 x 1 x 3e9, have 43 digits and do not fit int64 at all).

    >>> import numpy as np
    >>> num, den = circumcenters(np.array([[[0, 0, 0], [2, 0, 0], [0, 2, 0], [0, 0, 4]]]), (1, 1, 1))
    >>> num.tolist(), den.tolist()
    ([[1, 1, 2]], [[1, 1, 1]])
    """
    import numpy as np

    p = np.asarray(tets, dtype=np.int64)
    d = p[:, 1:] - p[:, :1]
    extent = int(np.abs(d).max(initial=0))
    bound = 24 * max(weights) * extent ** 3 * (int(np.abs(p).max(initial=0)) + extent + 1)
    if python_integers or bound >= 2**62:
        d, w = d.astype(object), np.array(weights, dtype=object)
    else:
        w = np.array(weights, dtype=np.int64)
    det, numerators = _cramer(d, w)
    nums, dens = [], []
    for axis in range(3):
        den = 2 * w[axis] * det
        num = p[:, 0, axis].astype(den.dtype) * den + numerators[axis]
        sign = np.where(den < 0, -1, 1)
        num, den = num * sign, den * sign
        g = np.gcd(num, den) if den.dtype != object else np.frompyfunc(math.gcd, 2, 1)(num, den)
        nums.append(num // g)
        dens.append(den // g)
    return np.stack(nums, axis=1), np.stack(dens, axis=1)


def _cramer(d: NDArray[Any], w: NDArray[Any]) -> tuple[NDArray[Any], list[NDArray[Any]]]:
    """The sphere through the origin and the rows d1, d2, d3 of ``d`` (n, 3, 3), in bulk: its centre c
    solves 2 W c . d_k = L(d_k) (L the lifted length, ``w`` . d_k^2), so W c = N / (2 det) for M the
    rows d_k, by Cramer's rule in integers.  Returns (det, [N_x, N_y, N_z]) in ``d``'s dtype; the
    callers bound them (:func:`sphere_sides`, :func:`circumcenters`)."""
    import numpy as np

    lifted = (d * d * w).sum(axis=2)  # (n, 3): |d_k|^2 in the weighted metric
    det = np.einsum("ij,ij->i", d[:, 0], np.cross(d[:, 1], d[:, 2]))
    numerators = []
    for axis in range(3):
        m = d.copy()
        m[:, :, axis] = lifted
        numerators.append(np.einsum("ij,ij->i", m[:, 0], np.cross(m[:, 1], m[:, 2])))
    return det, numerators


# ---------------------------------------------------------------------------------------------
# One point set: its integer frame, with the predicates and constructions above on its points
# ---------------------------------------------------------------------------------------------

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

    def side_at(self, point: Sequence[int], weights: Sequence[int], divisor: int = 1) -> int:
        """The side of the point ``point / divisor`` (frame coordinates, ``weights`` the frame's), times
        ``divisor**2``: the same sign as :meth:`side`, in integers, the point lifted here."""
        a, b, c, d = self.normal
        x, y, z = point
        lifted = weights[0] * x * x + weights[1] * y * y + weights[2] * z * z
        return (a * x + b * y + c * z) * divisor + d * lifted - self.offset * divisor * divisor

    def pencil(self, normal: Sequence[int], offset: int, h: int, g: int) -> "Sphere":
        """The sphere ``g * self - h * plane`` of the pencil through the circle where the plane
        ``normal . x = offset`` meets this sphere (``g > 0`` keeps the lifted coefficient positive)."""
        a, b, c, d = self.normal
        return Sphere((g * a - h * normal[0], g * b - h * normal[1], g * c - h * normal[2], g * d),
                      g * self.offset - h * offset)

    def scaled(self, g: int) -> "Sphere":
        """The sphere :meth:`Frame.sphere` gives for the same four points with every coordinate times
        ``g`` (about the origin): the coordinates scale by ``g`` and the lifted one by ``g**2``, so the
        cofactors scale by ``g**4`` (x, y, z) and ``g**3`` (lifted), the offset by ``g**5``."""
        n0, n1, n2, n3 = self.normal
        return Sphere((g ** 4 * n0, g ** 4 * n1, g ** 4 * n2, g ** 3 * n3), g ** 5 * self.offset)


@dataclass(frozen=True)
class Frame:
    """Integer coordinates of a point set in a box, with exact predicates."""

    ids: tuple[int, ...]
    coords: tuple[_Vector, ...]
    lifted: tuple[tuple[int, int, int, int], ...]
    scale: int
    weights: _Vector

    @classmethod
    def build(cls, unit_points: Mapping[int, Sequence[Rational]], squared_lengths: Sequence[Rational]) -> "Frame":
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
        return cls(ids, cast("tuple[_Vector, ...]", coords), cast("tuple[tuple[int, int, int, int], ...]", lifted),
                   scale, cast(_Vector, weights))

    def orient(self, i: int, j: int, k: int, m: int) -> int:
        """Sign-bearing 6x volume of (i, j, k, m), indices into ``coords``; > 0 when right-handed."""
        p = self.coords[i]
        return determinant(sub(self.coords[j], p), sub(self.coords[k], p), sub(self.coords[m], p))

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

    def spanning(self, members: Sequence[int]) -> tuple[int, int, int, int] | None:
        """The first four of ``members`` (in the order of their combinations) not in one plane; ``None``
        when every four are: the members are flat."""
        return next((quad for quad in combinations(members, 4) if self.orient(*quad) != 0), None)

    def circumsphere(self, members: Sequence[int]) -> Sphere | None:
        """The sphere through all of ``members`` (indices into ``coords``): ``None`` when they are flat
        or not co-spherical.  The sphere of the first four not in one plane (the first that has one)."""
        sphere = next((s for s in (self.sphere(*quad) for quad in combinations(members, 4)) if s is not None), None)
        if sphere is None or any(sphere.side(self.lifted[m]) != 0 for m in members):
            return None
        return sphere

    def center(self, sphere: Sphere) -> tuple[Fraction, Fraction, Fraction]:
        """Exact unit coordinates of a sphere's center."""
        n = sphere.normal
        return cast("tuple[Fraction, Fraction, Fraction]",
                    tuple(Fraction(-n[axis], 2 * self.weights[axis] * n[3] * self.scale) for axis in range(3)))

    def real_dot(self, u: Sequence[int], v: Sequence[int]) -> int:
        """A positive multiple of the real dot product of two frame vectors."""
        return sum(w * x * y for w, x, y in zip(self.weights, u, v))

    def right_angled(self, cycle: Sequence[int]) -> bool:
        """Whether every real angle of the polygon ``cycle`` (indices into ``coords``) is right."""
        points = [self.coords[i] for i in cycle]
        edges = [sub(q, p) for p, q in zip(points, points[1:] + points[:1])]
        return all(self.real_dot(e, f) == 0 for e, f in zip(edges, edges[1:] + edges[:1]))
