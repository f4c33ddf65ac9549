"""A convex polyhedron given by corners, edges and faces, checked exactly: what a base element is.

:meth:`cospherical.core.shapes.Shape.from_vertices` takes a shape as a user writes it
(a shape file, a list of corners and the corner numbers of its edges and faces) and
calls :func:`convex_polyhedron`, which refuses anything that is not one closed convex
surface with one clear line, and orients every face counter-clockwise seen from
outside with its outward plane.  Everything is decided on exact unit coordinates.
"""

from __future__ import annotations

from fractions import Fraction
from itertools import combinations
from typing import Any, Sequence

from ..errors import InputError
from .box import Point
from .exact import parse_rational
from .geometry import area_vector, collinear, cross, dot, plane_normal, sub, tetra_six_volume

__all__ = ["Plane", "convex_polyhedron"]

Plane = tuple[tuple[Fraction, Fraction, Fraction], Fraction]
"""An outward face plane ``normal . x <= offset`` in unit coordinates."""

# A base element of a mesh has a handful of corners; its tessellation's exact tests grow
# with their number, so a shape file of thousands is refused before any is read.
_MAX_CORNERS = 64


def _point(value: Any, where: str) -> Point:
    if isinstance(value, str) or not hasattr(value, "__len__") or len(value) != 3:
        raise InputError(f"{where} {value!r}: needs three coordinates")
    x, y, z = (parse_rational(x, where) for x in value)
    return (x, y, z)


def _index(value: object, count: int, where: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < count:
        raise InputError(f"{where}: {value!r} is not a corner number 0..{count - 1}")
    return value


def convex_polyhedron(vertices: Sequence[Any], edges: Sequence[Any], faces: Sequence[Any], name: str = "element"
                      ) -> tuple[tuple[Point, ...], tuple[tuple[int, int], ...], tuple[tuple[int, ...], ...],
                                 tuple[Plane, ...]]:
    """``(corners, edges, faces, planes)`` of a convex polyhedron, checked exactly.

    ``vertices`` are unit coordinates (numbers or exact texts), ``edges`` corner pairs,
    ``faces`` corner cycles in either orientation; the faces come back turned
    counter-clockwise seen from outside, each with its outward plane.  Refused with an
    :class:`~cospherical.errors.InputError` naming the problem (``name``: the shape's):
    repeated corners, a face that is not a plane convex polygon, a corner outside a
    face's half-space (not convex) or in its plane without being one of its corners
    (not a vertex), edges that are not the faces' sides, a surface that is not closed.

    Examples
    --------
    >>> corners, edges, faces, planes = convex_polyhedron(
    ...     [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)], [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)],
    ...     [(0, 1, 2), (0, 1, 3), (1, 2, 3), (2, 0, 3)])
    >>> faces[0], planes[0]
    ((0, 2, 1), ((Fraction(0, 1), Fraction(0, 1), Fraction(-1, 1)), Fraction(0, 1)))
    """
    if not all(isinstance(x, Sequence) and not isinstance(x, str) for x in (vertices, edges, faces)):
        raise InputError(f"{name}: corners, edges and faces must be lists")
    if not 4 <= len(vertices) <= _MAX_CORNERS:
        raise InputError(f"{name}: needs 4 to {_MAX_CORNERS} corners, got {len(vertices)}")
    # a convex polyhedron has at most 2n - 4 faces and 3n - 6 edges: longer lists are refused unread
    if len(faces) > 2 * len(vertices) or len(edges) > 3 * len(vertices):
        raise InputError(f"{name}: {len(faces)} faces and {len(edges)} edges: more than {len(vertices)} "
                         "corners of a convex polyhedron can have")
    corners = tuple(_point(v, f"corner {i}") for i, v in enumerate(vertices))
    n = len(corners)
    first: dict[Point, int] = {}
    for j, corner in enumerate(corners):
        i = first.setdefault(corner, j)
        if i != j:
            raise InputError(f"{name}: corners {i} and {j} are the same point")
    # Coplanar in one pass, exactly: a corner off the line of corners 0 and 1 spans their
    # plane (none: all on one line); the corners are a solid iff one is off that plane.
    p, q = corners[0], corners[1]
    r = next((c for c in corners[2:] if not collinear(p, q, c)), None)
    if r is None or all(tetra_six_volume(p, q, r, c) == 0 for c in corners[2:]):
        raise InputError(f"{name}: the corners are coplanar: no solid")
    cycles = []
    for f, face in enumerate(faces):
        if isinstance(face, str) or not hasattr(face, "__len__") or len(face) < 3:
            raise InputError(f"{name}: face {f} {face!r}: needs at least three corners")
        cycle = tuple(_index(v, n, f"{name}: face {f}") for v in face)
        if len(set(cycle)) != len(cycle):
            raise InputError(f"{name}: face {f} {list(cycle)}: a corner appears twice")
        cycles.append(cycle)
    oriented, planes = [], []
    for f, cycle in enumerate(cycles):
        cycle, plane = _oriented_face(corners, cycle, f, name)
        oriented.append(cycle)
        planes.append(plane)
    sides: dict[frozenset[int], list[int]] = {}
    for f, cycle in enumerate(oriented):
        for a, b in zip(cycle, cycle[1:] + cycle[:1]):
            sides.setdefault(frozenset((a, b)), []).append(f)
    bad = next((sorted(e) for e, fs in sides.items() if len(fs) != 2), None)
    if bad is not None:
        raise InputError(f"{name}: edge {bad[0]}-{bad[1]} belongs to {len(sides[frozenset(bad)])} faces: "
                         "the faces do not close the surface")
    missing = [i for i in range(n) if not any(i in c for c in oriented)]
    if missing:
        raise InputError(f"{name}: corner {missing[0]} is on no face")
    pairs = []
    for k, edge in enumerate(edges):
        if isinstance(edge, str) or not hasattr(edge, "__len__") or len(edge) != 2:
            raise InputError(f"{name}: edge {k} {edge!r}: needs two corners")
        pair = (_index(edge[0], n, f"{name}: edge {k}"), _index(edge[1], n, f"{name}: edge {k}"))
        if frozenset(pair) not in sides:
            raise InputError(f"{name}: edge {k} {list(pair)} is not a side of any face")
        pairs.append(pair)
    if len({frozenset(p) for p in pairs}) != len(pairs):
        raise InputError(f"{name}: an edge is given twice")
    if len(pairs) != len(sides):
        unlisted = sorted(sorted(e) for e in sides if e not in {frozenset(p) for p in pairs})[0]
        raise InputError(f"{name}: the side {unlisted[0]}-{unlisted[1]} of a face is not among the edges")
    if n - len(pairs) + len(oriented) != 2:
        raise InputError(f"{name}: V - E + F = {n - len(pairs) + len(oriented)}, not 2: "
                         "not one closed convex surface")
    return corners, tuple(pairs), tuple(oriented), tuple(planes)


def _oriented_face(corners: Sequence[Point], cycle: tuple[int, ...], f: int, name: str
                   ) -> tuple[tuple[int, ...], Plane]:
    """The cycle counter-clockwise seen from outside and the outward plane, after the checks."""
    pts = [corners[i] for i in cycle]
    m = len(cycle)
    normal = area_vector(pts)  # Newell's normal: exact, and nonzero for any convex polygon
    if normal == (0, 0, 0):  # a self-crossing order can cancel Newell's sum: any corner triple then
        normal = next((n for a, b, c in combinations(pts, 3) if (n := plane_normal(a, b, c)) != (0, 0, 0)),
                      normal)
    if normal == (0, 0, 0):
        raise InputError(f"{name}: face {f} {list(cycle)}: its corners are on one line")
    offset = dot(normal, pts[0])
    if any(dot(normal, p) != offset for p in pts):
        raise InputError(f"{name}: face {f} {list(cycle)}: its corners are not on one plane")
    for i in range(m):
        # Convex in the given order: every other corner strictly on the inner side of each side.
        p, q = pts[i], pts[(i + 1) % m]
        inward = cross(normal, sub(q, p))
        if any(dot(inward, sub(r, p)) <= 0 for j, r in enumerate(pts) if j not in (i, (i + 1) % m)):
            raise InputError(f"{name}: face {f} {list(cycle)}: not a convex polygon in this order "
                             "(or three corners on a line)")
    above = below = False
    for i, p in enumerate(corners):
        if i in cycle:
            continue
        side = dot(normal, p) - offset
        if side == 0:
            raise InputError(f"{name}: corner {i} lies in the plane of face {f} {list(cycle)} without being one "
                             "of its corners")
        above, below = above or side > 0, below or side < 0
    if above and below:
        raise InputError(f"{name}: not convex: corners lie on both sides of face {f} {list(cycle)}")
    if above:  # the normal points inwards: turn the face round
        cycle = (cycle[0], *reversed(cycle[1:]))
        normal, offset = (-normal[0], -normal[1], -normal[2]), -offset
    return cycle, ((Fraction(normal[0]), Fraction(normal[1]), Fraction(normal[2])), Fraction(offset))
