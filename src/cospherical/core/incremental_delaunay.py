"""A Delaunay tetrahedralisation of any point set, built incrementally in integers (no floats at all).

The points are integer grid coordinates with integer weights proportional to the
squared box lengths (the frame of :mod:`cospherical.core.geometry`), so every
decision below is an exact orientation or in-sphere determinant of that module,
whatever the box's aspect ratio: a 1e-12 x 1 x 3e9 domain, where a float
triangulation (Qhull) finds its first simplex flat, is decided like a cube.

Bowyer-Watson with CGAL's infinite vertex:

* The triangulation covers the whole space: besides the finite tetrahedra, each
  hull face f is joined to a vertex at infinity.  Every tetrahedron is stored
  positively oriented; for an infinite one, replacing the infinite vertex by a
  point q gives a positive orientation exactly when q is strictly beyond f.
* A new point p conflicts with a finite tetrahedron when it lies strictly inside
  its circumsphere, and with an infinite one when it lies strictly beyond f, or
  in f's plane and strictly inside f's circumcircle (decided as "strictly inside
  the sphere of the finite tetrahedron across f", whose sphere meets that plane
  in the circle).  The conflict region is connected (the caps beyond a face of a
  Delaunay triangulation are nested), so it is found by a search from the
  tetrahedron the walk ends in.
* The cavity is replaced by p joined to its boundary faces: each new
  tetrahedron is a conflicting one with the vertex opposite a boundary face
  replaced by p.  Strictness is what keeps them solid: were p in the plane of a
  boundary face, it would be strictly inside that face's circle and so in
  conflict with both tetrahedra on the face, which is then not a boundary face.
  Co-spherical points therefore never make a flat tetrahedron; ties stay in the
  triangulation as any choice among the equivalent ones, and the cells (all
  points on one empty sphere) follow by grouping tetrahedra with equal spheres.
* Point location: a visibility walk from the last new tetrahedron, stepping across
  a face that p lies strictly beyond, the face to try first turned by a counter
  so that no cycle of ties can hold it (a stochastic walk made deterministic); should a
  walk take more steps than there are tetrahedra, a scan of them all finds the one.

Points are inserted in Morton order of their coordinates, so the walk is short.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from ..errors import InputError, shown
from .geometry import Frame, collinear
from .morton import morton_codes

__all__ = ["delaunay_tetrahedra"]

_INFINITE = -1
# the three other indices of a tetrahedron, as an even permutation after the first
_FACES = ((1, 2, 3), (0, 3, 2), (0, 1, 3), (0, 2, 1))
# per index of the new point: the other indices, and per other index k the two left when k is left out too
_OTHERS = tuple(tuple(k for k in range(4) if k != at) for at in range(4))
_PAIRS = tuple({k: tuple(j for j in range(4) if j not in (at, k)) for k in _OTHERS[at]} for at in range(4))


def delaunay_tetrahedra(coords: Sequence[Sequence[int]], weights: Sequence[int]) -> list[tuple[int, int, int, int]]:
    """A Delaunay tetrahedralisation of integer points: tetrahedra as index quadruples, positively oriented.

    ``weights``: three positive integers proportional to the squared lengths of the
    three axes' units (the metric is ``w0 dx^2 + w1 dy^2 + w2 dz^2``; a weight of 0
    or below is no metric, and every point would seem to coincide with another or
    lie on every sphere).  Every tetrahedron has positive volume, no point strictly
    inside its circumsphere, and they tile the convex hull; where more than four
    points share an empty sphere the split among them is any one.  Raises
    :class:`~cospherical.errors.InputError` (a ``ValueError``) when a coordinate or
    weight is not an integer (a float is refused, never truncated), a weight is not
    positive, the points are coplanar or two of them coincide.

    Examples
    --------
    >>> cube = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    >>> tets = delaunay_tetrahedra(cube, (1, 4, 9))  # one cell: any split of the cube
    >>> len(tets), sorted(set().union(*tets))
    (6, [0, 1, 2, 3, 4, 5, 6, 7])
    >>> delaunay_tetrahedra(cube, (0, 1, 1))
    Traceback (most recent call last):
    ...
    cospherical.errors.InputError: weights (0, 1, 1): three positive integers (squared lengths of the axes' units)
    """
    weights = tuple(weights) if isinstance(weights, (Sequence, np.ndarray)) else (weights,)
    if len(weights) != 3 or not all(_is_integer(w) and w > 0 for w in weights):
        raise InputError(f"weights {shown(weights)}: three positive integers (squared lengths of the axes' units)")
    weights = [int(w) for w in weights]
    points = []
    for n, p in enumerate(coords):
        p = tuple(p) if isinstance(p, (Sequence, np.ndarray)) else (p,)
        if len(p) != 3 or not all(_is_integer(x) for x in p):
            raise InputError(f"point {n} {shown(p)}: three integer grid coordinates")
        points.append(tuple(int(x) for x in p))
    if len(points) < 4:
        raise InputError(f"{len(points)} points: a tetrahedralisation needs four that are not coplanar")
    low = [min(p[axis] for p in points) for axis in range(3)]
    frame = Frame.build({i: [x - m for x, m in zip(p, low)] for i, p in enumerate(points)}, weights)
    return _Triangulation(frame).run(_morton_order(frame.coords))


def _is_integer(value: object) -> bool:
    """An int or a numpy integer; not a bool, and never a float, however whole."""
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def _morton_order(coords: Sequence[Sequence[int]]) -> list[int]:
    codes = morton_codes(coords).tolist()
    return sorted(range(len(coords)), key=lambda i: (codes[i], coords[i]))


class _Triangulation:
    """Tetrahedra as parallel lists: vertices, neighbours (opposite each vertex), alive, cached spheres."""

    def __init__(self, frame: Frame) -> None:
        self.frame = frame
        self.vertices: list[list[int]] = []
        self.neighbours: list[list[int]] = []
        self.alive: list[bool] = []
        self.spheres: list[tuple[int, int, int, int, int] | None] = []
        self.free: list[int] = []  # slots of removed tetrahedra, reused: memory stays that of the live ones
        self.turn = 0

    def orient(self, a: int, b: int, c: int, d: int) -> int:
        return self.frame.orient(a, b, c, d)

    def _new(self, vertices: list[int]) -> int:
        if self.free:
            t = self.free.pop()
            self.vertices[t] = vertices
            self.neighbours[t] = [-1, -1, -1, -1]
            self.alive[t] = True
            return t
        self.vertices.append(vertices)
        self.neighbours.append([-1, -1, -1, -1])
        self.alive.append(True)
        self.spheres.append(None)
        return len(self.vertices) - 1

    def _first(self, order: list[int]) -> tuple[list[int], list[int]]:
        """Four points of ``order`` that span space (the first such, in order), and the rest in order."""
        frame = self.frame
        a = order[0]
        chosen = [a]
        for i in order[1:]:
            if len(chosen) == 1:
                ok = frame.coords[i] != frame.coords[a]
                if not ok:
                    raise InputError(f"points {a} and {i} coincide")
            elif len(chosen) == 2:
                ok = not collinear(frame.coords[a], frame.coords[chosen[1]], frame.coords[i])
            else:
                ok = self.orient(chosen[0], chosen[1], chosen[2], i) != 0
            if ok:
                chosen.append(i)
                if len(chosen) == 4:
                    break
        if len(chosen) < 4:
            raise InputError("the points are coplanar: no tetrahedralisation")
        first = set(chosen)
        rest = [i for i in order if i not in first]
        return chosen, rest

    def run(self, order: list[int]) -> list[tuple[int, int, int, int]]:
        (a, b, c, d), rest = self._first(order)
        if self.orient(a, b, c, d) < 0:
            b, c = c, b
        finite = self._new([a, b, c, d])
        for k in range(4):
            face = [self.vertices[finite][j] for j in _FACES[k]]
            # the face seen from outside: reversed, with the infinite vertex where the opposite one was
            outside = [0, 0, 0, 0]
            outside[k] = _INFINITE
            outside[_FACES[k][0]], outside[_FACES[k][1]], outside[_FACES[k][2]] = face[0], face[2], face[1]
            t = self._new(outside)
            self.neighbours[finite][k] = t
            self.neighbours[t][k] = finite
        self._link([(t, self.vertices[t].index(_INFINITE)) for t in (1, 2, 3, 4)])
        self.last = finite
        for p in rest:
            self._insert(p)
        return [(v[0], v[1], v[2], v[3]) for v, alive in zip(self.vertices, self.alive) if alive and _INFINITE not in v]

    def _link(self, tets: list[tuple[int, int]]) -> None:
        """Join new tetrahedra ``(tetrahedron, index of the new point in it)`` across their faces through the point.

        Each such face is in exactly two of them (the cavity's boundary is a closed
        surface); it is named by its two other vertices.
        """
        open_faces: dict[tuple[int, int], tuple[int, int]] = {}
        vertices_of, neighbours_of = self.vertices, self.neighbours
        for t, at in tets:
            vertices = vertices_of[t]
            for k in _OTHERS[at]:
                i, j = _PAIRS[at][k]
                a, b = vertices[i], vertices[j]
                key = (a, b) if a < b else (b, a)
                other = open_faces.pop(key, None)
                if other is None:
                    open_faces[key] = (t, k)
                else:
                    neighbours_of[t][k] = other[0]
                    neighbours_of[other[0]][other[1]] = t
        if open_faces:
            raise AssertionError("the cavity's boundary is not closed")

    def _sphere(self, t: int) -> tuple[int, int, int, int, int]:
        sphere = self.spheres[t]
        if sphere is None:
            found = self.frame.sphere(*self.vertices[t])
            assert found is not None, "a finite tetrahedron of the triangulation is solid"
            sphere = (*found.normal, found.offset)
            self.spheres[t] = sphere
        return sphere

    def _inside_sphere(self, t: int, p: int) -> bool:
        a, b, c, d, offset = self._sphere(t)
        x, y, z, w = self.frame.lifted[p]
        return a * x + b * y + c * z + d * w < offset

    def _conflict(self, t: int, p: int) -> bool:
        vertices = self.vertices[t]
        if _INFINITE not in vertices:
            return self._inside_sphere(t, p)
        k = vertices.index(_INFINITE)
        replaced = list(vertices)
        replaced[k] = p
        side = self.orient(*replaced)
        if side:
            return side > 0
        return self._inside_sphere(self.neighbours[t][k], p)

    def _locate(self, p: int) -> int:
        """A tetrahedron in conflict with p: a finite one whose closure holds p, or an infinite one p is beyond."""
        t = self.last
        if not self.alive[t] or _INFINITE in self.vertices[t]:
            t = next(i for i in range(len(self.vertices) - 1, -1, -1)
                     if self.alive[i] and _INFINITE not in self.vertices[i])
        orient, vertices, neighbours = self.orient, self.vertices, self.neighbours
        for _ in range(len(vertices) + 16):
            self.turn = (self.turn + 1) & 3
            here = vertices[t]
            for step in range(4):
                k = (self.turn + step) & 3
                replaced = list(here)
                replaced[k] = p
                if orient(*replaced) < 0:
                    t = neighbours[t][k]
                    break
            else:
                return t
            if _INFINITE in vertices[t]:
                return t
        return self._scan(p)

    def _scan(self, p: int) -> int:
        """What the walk finds, by looking at every tetrahedron: the walk's guard, should it ever go round in circles."""
        for t, (here, alive) in enumerate(zip(self.vertices, self.alive)):
            if alive and (self._conflict(t, p) if _INFINITE in here else
                          all(self.orient(*(p if m == k else v for m, v in enumerate(here))) >= 0 for k in range(4))):
                return t
        raise AssertionError("no tetrahedron holds the point")

    def _insert(self, p: int) -> None:
        start = self._locate(p)
        if not self._conflict(start, p):
            raise InputError(f"point {p} coincides with a vertex")
        cavity = {start}
        stack = [start]
        boundary: list[tuple[int, int]] = []
        neighbours, spheres = self.neighbours, self.spheres
        x, y, z, w = self.frame.lifted[p]
        while stack:
            t = stack.pop()
            for k in range(4):
                u = neighbours[t][k]
                if u in cavity:
                    continue
                sphere = spheres[u]  # the finite tetrahedra's in-sphere test, inlined: the innermost loop
                if sphere is not None:
                    a, b, c, d, offset = sphere
                    conflict = a * x + b * y + c * z + d * w < offset
                else:
                    conflict = self._conflict(u, p)
                if conflict:
                    cavity.add(u)
                    stack.append(u)
                else:
                    boundary.append((t, k))
        new = []
        for t, k in boundary:
            vertices = list(self.vertices[t])
            vertices[k] = p
            n = self._new(vertices)
            outside = neighbours[t][k]
            neighbours[n][k] = outside
            there = neighbours[outside]
            there[there.index(t)] = n
            new.append((n, k))
        for t in cavity:
            self.alive[t] = False
            self.spheres[t] = None
        self.free.extend(sorted(cavity))
        self._link(new)
        self.last = next((n for n, _ in new if _INFINITE not in self.vertices[n]), self.last)
