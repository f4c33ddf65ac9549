"""Base elements: the cuboid, prisms, pyramids, tetrahedra, any convex polyhedron, in a box.

The paper's conclusion says its algorithm tessellates "any 1-irregular convex
configuration" unchanged; this module is that generalisation, with the cuboid
one standard shape among the others.  A :class:`Shape` is a convex polyhedron
given by exact corners in *unit* coordinates (s, t, u), scaled by a box
A x B x C (the real point is (s*A, t*B, u*C)), its edges and its faces.
Because the map from unit to real coordinates is a positive diagonal scaling,
convexity, planarity and orientation are decided on the unit coordinates, and
everything metric goes through the box's squared lengths
(:mod:`cospherical.core.geometry`): the whole pipeline stays exact for
``sqrt(2)`` boxes too.

Node numbering: the corners in the order given (VTK order for the standard
shapes), then one node per edge (edge k carries node ``len(corners) + k``), then
one node per quadrilateral face, in face order, then, for a parallelepiped, the
body point.  For the cuboid: corners 0-7, edge points 8-19, face points 20-25,
body point 26 (:mod:`cospherical.core.box` draws them).  A Steiner point on edge k
sits at parameter t in (0, 1) from the edge's *lower end* (its lexicographically
smallest corner in unit coordinates; for the axis-parallel edges of a cuboid
this is the lower-coordinate end).  A quadrilateral face may carry a point when
its four edges are split with opposite edges at the same parameter (measured in
the same direction); the point is where the two cut lines cross.  Triangles
carry nothing: a refined neighbour puts nothing there.  The body point of a
parallelepiped needs a point on all six faces (the element refined into eight).

The box and the cuboid's numbering are :mod:`cospherical.core.box`'s (importable
from here too), the exact checks of corners, edges and faces
:func:`cospherical.core.convex.convex_polyhedron`'s.
Their configurations are :class:`cospherical.core.configuration.Configuration`,
their tessellation :func:`cospherical.core.tessellation.tessellate`, their
isometries :func:`cospherical.core.symmetry.shape_symmetries`.

Examples
--------
>>> prism = standard_shape("prism")
>>> len(prism.corners), len(prism.edges), prism.quad_faces
(6, 9, (2, 3, 4))
>>> cuboid = standard_shape("cuboid")
>>> cuboid.quad_faces, cuboid.body_node
((0, 1, 2, 3, 4, 5), 26)
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from functools import cached_property
from itertools import combinations
from typing import Any, Iterable, Sequence

from ..caches import cached
from ..errors import InputError
from .box import CORNERS, EDGES, FACE_EDGES, FACES, Box, Point, edge_axis
from .codes import mask_codes
from .convex import Plane, convex_polyhedron
from .geometry import Rational, dot, six_volume, sub

# Box, the cuboid's numbering and Point live in core.box, mask_codes in core.codes: importable from here too
__all__ = ["Box", "CORNERS", "EDGES", "ELEMENTS", "FACES", "FACE_EDGES", "Point", "STANDARD_SHAPES", "Shape",
           "edge_axis", "mask_codes", "standard_shape"]

_H = Fraction(1, 2)
# The standard shapes, corners in VTK order (hexahedron, wedge, pyramid, tetra), edges in the
# order of the VTK quadratic cells, faces as VTK lists them (oriented on building).  The
# cuboid's numbering is :mod:`cospherical.core.box`'s (face f carries node 20 + f).
STANDARD_SHAPES: dict[str, tuple[tuple[tuple[Rational, ...], ...], tuple[tuple[int, int], ...],
                                  tuple[tuple[int, ...], ...]]] = {
    "cuboid": (CORNERS, EDGES, FACES),
    "prism": (
        ((0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (0, 1, 1)),
        ((0, 1), (1, 2), (2, 0), (3, 4), (4, 5), (5, 3), (0, 3), (1, 4), (2, 5)),
        ((0, 1, 2), (3, 4, 5), (0, 1, 4, 3), (1, 2, 5, 4), (2, 0, 3, 5)),
    ),
    "pyramid": (
        ((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (_H, _H, _H)),
        ((0, 1), (1, 2), (2, 3), (3, 0), (0, 4), (1, 4), (2, 4), (3, 4)),
        ((0, 1, 2, 3), (0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)),
    ),
    "tetrahedron": (
        ((0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)),
        ((0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)),
        ((0, 1, 2), (0, 1, 3), (1, 2, 3), (2, 0, 3)),
    ),
}
ELEMENTS = tuple(STANDARD_SHAPES)
@dataclass(frozen=True)
class Shape:
    """A convex base element: exact corners, edges and faces, scaled by a box.

    Build it with :meth:`from_vertices` (which checks everything exactly) or
    :func:`standard_shape`.  ``faces`` are corner cycles, counter-clockwise seen
    from outside; ``planes`` their outward planes ``normal . x <= offset`` in unit
    coordinates; ``quad_faces`` the faces with four corners, whose points are the
    nodes after the edge nodes.
    """

    name: str
    box: Box
    corners: tuple[Point, ...]
    edges: tuple[tuple[int, int], ...]
    faces: tuple[tuple[int, ...], ...]
    planes: tuple[Plane, ...] = field(repr=False)

    @classmethod
    def from_vertices(cls, vertices: Sequence[Any], edges: Sequence[Any], faces: Sequence[Any],
                      box: Box | Iterable[str | int | Fraction] = ("1", "1", "1"), name: str = "element") -> "Shape":
        """A convex polyhedron from its vertices (unit coordinates), edges and faces, checked exactly.

        The faces may be given in either orientation; they are turned
        counter-clockwise seen from outside.  Refused with an
        :class:`~cospherical.errors.InputError` naming the problem: repeated
        corners, a face that is not a plane convex polygon, a corner outside a
        face's half-space (not convex) or in its plane without being one of its
        corners (not a vertex), edges that are not the faces' sides, a surface
        that is not closed.

        Examples
        --------
        >>> shape = Shape.from_vertices([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)],
        ...                             [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)],
        ...                             [(0, 1, 2), (0, 1, 3), (1, 2, 3), (2, 0, 3)])
        >>> shape.faces[0], shape.unit_volume
        ((0, 2, 1), Fraction(1, 6))
        >>> Shape.from_vertices([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)], [], [])
        Traceback (most recent call last):
        ...
        cospherical.errors.InputError: element: the corners are coplanar: no solid
        """
        box = box if isinstance(box, Box) else Box.parse(box)
        return cls(name, box, *convex_polyhedron(vertices, edges, faces, name))

    def __hash__(self) -> int:
        # Hashed once: a shape keys the caches of its symmetries and of its configurations' maps.
        return self._hash

    @cached_property
    def _hash(self) -> int:
        return hash((self.name, self.box, self.corners, self.edges, self.faces))

    def __getstate__(self) -> dict[str, Any]:
        # A string's hash differs from process to process: a pickled shape (a study's pool)
        # computes its hash again where it is unpickled.
        state = dict(self.__dict__)
        state.pop("_hash", None)
        return state

    @cached_property
    def quad_faces(self) -> tuple[int, ...]:
        """The faces with four corners: face ``quad_faces[q]`` carries node ``len(corners) + len(edges) + q``."""
        return tuple(f for f, face in enumerate(self.faces) if len(face) == 4)

    @cached_property
    def face_nodes(self) -> dict[int, int]:
        """Quadrilateral face -> the node of its point."""
        first = len(self.corners) + len(self.edges)
        return {f: first + q for q, f in enumerate(self.quad_faces)}

    @cached_property
    def parallelepiped(self) -> tuple[int, tuple[tuple[tuple[Rational, ...], tuple[int, ...]], ...]] | None:
        """``(corner, ((d0, edges0), (d1, edges1), (d2, edges2)))`` when the shape is a
        parallelepiped: every point is ``corner + x d0 + y d1 + z d2`` for x, y, z in [0, 1],
        each d running along the edges of its class from their lower ends; ``None`` for any
        other shape."""
        if len(self.corners) != 8 or len(self.quad_faces) != 6:
            return None
        classes: dict[tuple[Rational, ...], list[int]] = {}
        for k in range(len(self.edges)):
            d = sub(self.corners[self._edge_end[k]], self.corners[self.edge_start(k)])
            classes.setdefault(d, []).append(k)
        if len(classes) != 3:
            return None
        origin = min(range(8), key=lambda i: self.corners[i])
        return origin, tuple((d, tuple(edges)) for d, edges in classes.items())

    @property
    def body_node(self) -> int | None:
        """The node of the body point (a parallelepiped's; ``None``: the shape has none)."""
        if self.parallelepiped is None:
            return None
        return len(self.corners) + len(self.edges) + len(self.quad_faces)

    @cached_property
    def unit_volume(self) -> Fraction:
        """The volume as a fraction of the box's."""
        return Fraction(six_volume(self.corners, self.faces)) / 6

    def edge_start(self, k: int) -> int:
        """The corner from which edge k's parameter is measured: its lexicographically smallest."""
        return self._edge_starts[k]

    @cached_property
    def _edge_starts(self) -> tuple[int, ...]:
        return tuple(min(edge, key=lambda i: self.corners[i]) for edge in self.edges)

    @cached_property
    def _edge_end(self) -> tuple[int, ...]:
        return tuple(j if i == start else i for (i, j), start in zip(self.edges, self._edge_starts))

    @cached_property
    def _edge_lines(self) -> tuple[tuple[Point, tuple[tuple[int, Rational], ...]], ...]:
        # Per edge: its start point and the axes along which it runs, with the extent on each.
        lines = []
        for k in range(len(self.edges)):
            p, q = self.corners[self.edge_start(k)], self.corners[self._edge_end[k]]
            lines.append((p, tuple((a, q[a] - p[a]) for a in range(3) if q[a] != p[a])))
        return tuple(lines)

    def edge_point(self, k: int, t: Fraction) -> Point:
        """The point at parameter t of edge k, exactly."""
        start, runs = self._edge_lines[k]
        point = list(start)
        for axis, extent in runs:  # the coordinates along which the edge does not run stay
            point[axis] = t if extent == 1 and start[axis] == 0 else start[axis] + t * extent
        return (point[0], point[1], point[2])

    def face_point(self, f: int, t: Fraction, s: Fraction) -> Point:
        """The point of quadrilateral face f (cycle c0 c1 c2 c3) where its two cut lines cross: the
        line through the points at t on sides c0->c1 and c3->c2, and the one through the points
        at s on sides c0->c3 and c1->c2."""
        parallelogram = self._parallelograms.get(f)
        if parallelogram is not None:  # the cut lines run along its sides: c0 + t (c1 - c0) + s (c3 - c0)
            point = list(parallelogram[0])
            for axis, along_t, along_s in parallelogram[1]:
                x = point[axis]
                if along_t:
                    x = t if along_t == 1 and x == 0 else x + t * along_t
                if along_s:
                    x = s if along_s == 1 and x == 0 else x + s * along_s
                point[axis] = x
            return (point[0], point[1], point[2])
        c = [self.corners[i] for i in self.faces[f]]
        p = [a + t * (b - a) for a, b in zip(c[0], c[1])]
        q = [a + t * (b - a) for a, b in zip(c[3], c[2])]
        r = [a + s * (b - a) for a, b in zip(c[0], c[3])]
        u = [a + s * (b - a) for a, b in zip(c[1], c[2])]
        # p + x (q - p) = r + y (u - r): two of the three coordinate equations have
        # a nonzero determinant, because the cut lines of a convex face cross.
        d1, d2, e = sub(q, p), sub(u, r), sub(r, p)
        for i, j in combinations(range(3), 2):
            det = d1[i] * -d2[j] + d2[i] * d1[j]
            if det:
                x = (e[i] * -d2[j] + d2[i] * e[j]) / det
                return (p[0] + x * d1[0], p[1] + x * d1[1], p[2] + x * d1[2])
        raise AssertionError("the cut lines of a convex face cross")  # pragma: no cover

    @cached_property
    def _parallelograms(self) -> dict[int, tuple[Point, tuple[tuple[int, Rational, Rational], ...]]]:
        # Per quadrilateral face that is a parallelogram: c0 and, per coordinate that varies over
        # the face, (axis, its change along c0->c1, along c0->c3); the face points of a
        # configuration are computed from these (the cuboid's coordinates are then t or s alone).
        found = {}
        for f in self.quad_faces:
            c = [self.corners[i] for i in self.faces[f]]
            if all(a + b == d + e for a, b, d, e in zip(c[0], c[2], c[1], c[3])):
                found[f] = (c[0], tuple((a, c[1][a] - c[0][a], c[3][a] - c[0][a]) for a in range(3)
                                        if c[1][a] != c[0][a] or c[3][a] != c[0][a]))
        return found

    def edge_index(self, i: int, j: int) -> int:
        return self._edge_index[frozenset((i, j))]

    @cached_property
    def _edge_index(self) -> dict[frozenset[int], int]:
        return {frozenset(e): k for k, e in enumerate(self.edges)}

    @cached_property
    def _bounds(self) -> tuple[tuple[tuple[int, Rational, Rational], ...],
                               tuple[tuple[tuple[Fraction, Fraction, Fraction], Fraction], ...]]:
        # A face plane normal to an axis bounds that coordinate alone: (axis, lower, upper) per
        # axis bounded on both sides this way (the box's three), and the other planes as they are.
        lower: dict[int, Rational] = {}
        upper: dict[int, Rational] = {}
        axis_planes: dict[int, list[tuple[tuple[Fraction, Fraction, Fraction], Fraction]]] = {}
        others = []
        for normal, offset in self.planes:
            axes = [a for a in range(3) if normal[a] != 0]
            if len(axes) == 1:
                quotient = offset / normal[axes[0]]
                bound = int(quotient) if quotient.denominator == 1 else quotient  # ints compare faster
                (upper if normal[axes[0]] > 0 else lower)[axes[0]] = bound
                axis_planes.setdefault(axes[0], []).append((normal, offset))
            else:
                others.append((normal, offset))
        both = tuple((a, lower[a], upper[a]) for a in range(3) if a in lower and a in upper)
        others += [plane for a, planes in axis_planes.items() if not (a in lower and a in upper) for plane in planes]
        return both, tuple(others)

    def contains(self, point: Sequence[Rational], closed: bool = True) -> bool:
        """Whether a point (unit coordinates) lies in the closed (or open) element, exactly."""
        axis_bounds, others = self._bounds
        if closed:
            return all(low <= point[a] <= high for a, low, high in axis_bounds) and \
                all(dot(normal, point) <= offset for normal, offset in others)
        return all(low < point[a] < high for a, low, high in axis_bounds) and \
            all(dot(normal, point) < offset for normal, offset in others)

    @cached_property
    def cut_sides(self) -> dict[int, tuple[tuple[int, bool], ...]]:
        """Quadrilateral face (cycle c0 c1 c2 c3) -> its sides c0->c1, c3->c2, c0->c3, c1->c2 (two
        pairs of opposite sides, each pair run the same way): (edge, whether the edge's parameter
        runs that way)."""
        sides = {}
        for f in self.quad_faces:
            c = self.faces[f]
            sides[f] = tuple((self.edge_index(a, b), self.edge_start(self.edge_index(a, b)) == a)
                             for a, b in ((c[0], c[1]), (c[3], c[2]), (c[0], c[3]), (c[1], c[2])))
        return sides


def standard_shape(name: str, box: Box | Iterable[str | int | Fraction] = ("1", "1", "1")) -> Shape:
    """One of the standard shapes (VTK hexahedron, wedge, pyramid, tetra) in a box A x B x C.

    ``cuboid``: the whole box, numbered as VTK's hexahedron (:data:`CORNERS`, :data:`EDGES`, :data:`FACES`);
    ``prism``: the right triangular prism (0,0,0) (A,0,0) (0,B,0) (0,0,C) (A,0,C) (0,B,C),
    half a box; ``pyramid``: the square pyramid on the box's bottom face with its
    apex at the box centre, a sixth of a box; ``tetrahedron``: the corner
    tetrahedron (0,0,0) (A,0,0) (0,B,0) (0,0,C).

    Examples
    --------
    >>> standard_shape("pyramid").unit_volume
    Fraction(1, 6)
    >>> standard_shape("cube")
    Traceback (most recent call last):
    ...
    cospherical.errors.InputError: element 'cube': choose one of cuboid, prism, pyramid, tetrahedron
    """
    if not isinstance(box, Box):
        lengths = tuple(box)
        texts = tuple(x for x in lengths if isinstance(x, str))
        # a box given as texts, as most callers give it, is parsed once
        box = _parsed_box(texts) if len(texts) == len(lengths) else Box.parse(lengths)
    return _standard_shape(name, box)


@cached(maxsize=64)
def _parsed_box(lengths: tuple[str, ...]) -> Box:
    return Box.parse(lengths)


@cached(maxsize=64)  # one object per shape and box: its symmetries and maps are cached on it
def _standard_shape(name: str, box: Box) -> Shape:
    if name not in STANDARD_SHAPES:
        raise InputError(f"element {name!r}: choose one of {', '.join(ELEMENTS)}")
    corners, edges, faces = STANDARD_SHAPES[name]
    return Shape.from_vertices(corners, edges, faces, box, name)
