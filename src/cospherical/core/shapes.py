"""1-irregular convex base elements other than the cuboid: prisms, pyramids, tetrahedra, any convex polyhedron.

The paper's conclusion says its algorithm tessellates "any 1-irregular convex
configuration" unchanged; this module is that generalisation.  A :class:`Shape`
is a convex polyhedron given by exact corners in *unit* coordinates (s, t, u),
scaled by a box A x B x C (the real point is (s*A, t*B, u*C)), its edges and its
faces.  Because the map from unit to real coordinates is a positive diagonal
scaling, convexity, planarity and orientation are decided on the unit
coordinates, and everything metric goes through the box's squared lengths, as
for cuboids (:mod:`cospherical.core.geometry`): the whole pipeline stays exact
for ``sqrt(2)`` boxes too.

Node numbering: the corners in the order given (VTK order for the standard
shapes), then one node per edge (edge k carries node ``len(corners) + k``), then
one node per quadrilateral face, in face order.  A Steiner point on edge k sits
at parameter t in (0, 1) from the edge's *lower end* (its lexicographically
smallest corner in unit coordinates; for the axis-parallel edges of a cuboid
this is the lower-coordinate end).  A quadrilateral face carries a point when
its four edges are split with opposite edges at the same parameter (measured in
the same direction); the point is where the two cut lines cross.  Triangles and
the interior carry nothing: a refined neighbour puts nothing there.

Their tessellation is :func:`cospherical.core.tessellation.tessellate`, as a cuboid's;
their isometries :func:`cospherical.core.symmetry.shape_symmetries`.

Examples
--------
>>> prism = standard_shape("prism")
>>> len(prism.corners), len(prism.edges), prism.quad_faces
(6, 9, (2, 3, 4))
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from functools import cached_property
from itertools import combinations
from typing import Iterable, Mapping, Sequence

from ..errors import InputError
from .codes import EDGE_DIGITS, digit_parameters, mask_codes, parameter_digits
from .configuration import CORNERS, EDGES, FACES, BaseConfiguration, Box, steiner_parameters
from .exact import parse_rational
from .geometry import area_vector, collinear, cross, dot, plane_normal, six_volume, sub, tetra_six_volume

__all__ = ["ELEMENTS", "STANDARD_SHAPES", "Shape", "ShapeConfiguration", "mask_codes", "standard_shape"]

Point = tuple[Fraction, Fraction, Fraction]

_H = Fraction(1, 2)
# The standard shapes, corners in VTK order (hexahedron, wedge, pyramid, tetra), edges in the
# order of the VTK quadratic cells, faces as VTK lists them (oriented on building).  The
# cuboid's numbering is the one of :mod:`cospherical.core.configuration` (face f carries
# node 20 + f: VTK's triquadratic hexahedron).
STANDARD_SHAPES: dict[str, tuple[tuple, tuple, tuple]] = {
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
# A base element of a mesh has a handful of corners; its tessellation's exact tests grow
# with their number, so a shape file of thousands is refused before any is read.
MAX_CORNERS = 64


def _point(value, where: str) -> Point:
    if isinstance(value, str) or not hasattr(value, "__len__") or len(value) != 3:
        raise InputError(f"{where} {value!r}: needs three coordinates")
    return tuple(parse_rational(x, where) for x in value)


def _index(value, count: int, where: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < count:
        raise InputError(f"{where}: {value!r} is not a corner number 0..{count - 1}")
    return value


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
    planes: tuple[tuple[tuple[Fraction, ...], Fraction], ...] = field(repr=False)

    @classmethod
    def from_vertices(cls, vertices: Sequence, edges: Sequence, faces: Sequence,
                      box: Box | Iterable = ("1", "1", "1"), name: str = "element") -> "Shape":
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
        if not all(isinstance(x, Sequence) and not isinstance(x, str) for x in (vertices, edges, faces)):
            raise InputError(f"{name}: corners, edges and faces must be lists")
        if not 4 <= len(vertices) <= MAX_CORNERS:
            raise InputError(f"{name}: needs 4 to {MAX_CORNERS} corners, got {len(vertices)}")
        # a convex polyhedron has at most 2n - 4 faces and 3n - 6 edges: longer lists are refused unread
        if len(faces) > 2 * len(vertices) or len(edges) > 3 * len(vertices):
            raise InputError(f"{name}: {len(faces)} faces and {len(edges)} edges: more than {len(vertices)} "
                             "corners of a convex polyhedron can have")
        corners = tuple(_point(v, f"corner {i}") for i, v in enumerate(vertices))
        n = len(corners)
        first: dict = {}
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
        sides = {}
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
            pair = tuple(_index(v, n, f"{name}: edge {k}") for v in edge)
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
        return cls(name, box, corners, tuple(pairs), tuple(oriented), tuple(planes))

    @cached_property
    def quad_faces(self) -> tuple[int, ...]:
        """The faces with four corners: face ``quad_faces[q]`` carries node ``len(corners) + len(edges) + q``."""
        return tuple(f for f, face in enumerate(self.faces) if len(face) == 4)

    @cached_property
    def unit_volume(self) -> Fraction:
        """The volume as a fraction of the box's."""
        return Fraction(six_volume(self.corners, self.faces)) / 6

    def edge_start(self, k: int) -> int:
        """The corner from which edge k's parameter is measured: its lexicographically smallest."""
        return min(self.edges[k], key=lambda i: self.corners[i])

    def edge_point(self, k: int, t: Fraction) -> Point:
        start = self.edge_start(k)
        end = self.edges[k][0] if self.edges[k][1] == start else self.edges[k][1]
        p, q = self.corners[start], self.corners[end]
        return tuple(a + t * (b - a) for a, b in zip(p, q))

    def edge_index(self, i: int, j: int) -> int:
        return self._edge_index[frozenset((i, j))]

    @cached_property
    def _edge_index(self) -> dict[frozenset[int], int]:
        return {frozenset(e): k for k, e in enumerate(self.edges)}

    def contains(self, point: Sequence[Fraction], closed: bool = True) -> bool:
        """Whether a point (unit coordinates) lies in the closed (or open) element, exactly."""
        if closed:
            return all(dot(normal, point) <= offset for normal, offset in self.planes)
        return all(dot(normal, point) < offset for normal, offset in self.planes)


def _oriented_face(corners, cycle, f, name):
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
        normal, offset = tuple(-x for x in normal), -offset
    return cycle, (tuple(Fraction(x) for x in normal), Fraction(offset))


def standard_shape(name: str, box: Box | Iterable = ("1", "1", "1")) -> Shape:
    """One of the standard shapes (VTK hexahedron, wedge, pyramid, tetra) in a box A x B x C.

    ``cuboid``: the whole box, numbered as :mod:`cospherical.core.configuration` numbers it;
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
    if name not in STANDARD_SHAPES:
        raise InputError(f"element {name!r}: choose one of {', '.join(ELEMENTS)}")
    corners, edges, faces = STANDARD_SHAPES[name]
    return Shape.from_vertices(corners, edges, faces, box, name)


@dataclass(frozen=True)
class ShapeConfiguration(BaseConfiguration):
    """A 1-irregular element of a :class:`Shape`: at most one Steiner point per edge.

    ``steiner[k]`` is the parameter of the point on edge k from its lower end,
    or ``None``.  Face points follow the ``octree`` policy (the paper's: every
    quadrilateral face whose four edges are split, opposite ones at the same
    parameter) or ``none``.

    Examples
    --------
    >>> cfg = ShapeConfiguration.from_code(standard_shape("pyramid"), "88880000")
    >>> sorted(cfg.nodes())[-1], cfg.point_faces
    (13, frozenset({0}))
    """

    shape: Shape
    steiner: tuple[Fraction | None, ...]
    face_points: str = "octree"

    def __post_init__(self) -> None:
        if len(self.steiner) != len(self.shape.edges):
            raise InputError(f"steiner: needs {len(self.shape.edges)} entries, got {len(self.steiner)}")
        if self.face_points not in ("octree", "none"):
            raise InputError(f"face-point policy {self.face_points!r}: choose one of octree, none")

    @classmethod
    def from_code(cls, shape: Shape, code: str, face_points: str = "octree") -> "ShapeConfiguration":
        """From one hexadecimal digit per edge (digit n: a point at t = n/16; ``0``: none)."""
        count = len(shape.edges)
        if not isinstance(code, str) or len(code) != count or not EDGE_DIGITS.match(code):
            raise InputError(f"configuration code {code!r}: the {shape.name} needs exactly {count} hexadecimal "
                             "digits, one per edge")
        return cls(shape, digit_parameters(code), face_points)

    @classmethod
    def from_steiner(cls, shape: Shape, steiner: Mapping | Iterable | None = None,
                     face_points: str = "octree") -> "ShapeConfiguration":
        """From ``{edge: t}`` or ``[(edge, t), ...]``, t a string, int or Fraction strictly between 0 and 1."""
        return cls(shape, steiner_parameters(steiner, len(shape.edges), shape.name), face_points)

    @property
    def box(self) -> Box:
        return self.shape.box

    @property
    def code(self) -> str | None:
        """One hexadecimal digit per edge; ``None`` when some t is not a multiple of 1/16."""
        return parameter_digits(self.steiner)

    @property
    def point_set_code(self) -> str | None:
        return self.code

    @property
    def has_body_point(self) -> bool:
        return False

    @cached_property
    def point_faces(self) -> frozenset[int]:
        """The quadrilateral faces carrying a point (face numbers of the shape)."""
        if self.face_points == "none":
            return frozenset()
        return frozenset(f for f in self.shape.quad_faces if self._face_parameters(f) is not None)

    def _face_parameters(self, f: int):
        # Along the face cycle (c0, c1, c2, c3): sides c0->c1 and c3->c2 are
        # opposite, as are c0->c3 and c1->c2; each needs the same parameter.
        c = self.shape.faces[f]
        params = []
        for a, b in ((c[0], c[1]), (c[3], c[2]), (c[0], c[3]), (c[1], c[2])):
            k = self.shape.edge_index(a, b)
            t = self.steiner[k]
            if t is None:
                return None
            params.append(t if self.shape.edge_start(k) == a else 1 - t)
        if params[0] != params[1] or params[2] != params[3]:
            return None
        return params[0], params[2]

    def _face_point(self, f: int) -> Point:
        c = [self.shape.corners[i] for i in self.shape.faces[f]]
        t, s = self._face_parameters(f)
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
                return tuple(a + x * b for a, b in zip(p, d1))
        raise AssertionError("the cut lines of a convex face cross")  # pragma: no cover

    def nodes(self) -> dict[int, Point]:
        """Node id -> exact unit coordinates: corners, edge points, face points."""
        shape = self.shape
        nodes = dict(enumerate(shape.corners))
        for k, t in enumerate(self.steiner):
            if t is not None:
                nodes[len(shape.corners) + k] = shape.edge_point(k, t)
        first = len(shape.corners) + len(shape.edges)
        for q, f in enumerate(shape.quad_faces):
            if f in self.point_faces:
                nodes[first + q] = self._face_point(f)
        return nodes

    def contains(self, point, closed: bool = True) -> bool:
        """Whether a point (unit coordinates) lies in the closed (or open) base element, exactly: the FVM test."""
        return self.shape.contains(point, closed)
