"""1-irregular cuboid configurations: box, Steiner points, node numbering.

Node numbering (shared by every part and file format, see design.md): corners
0-7 in VTK hexahedron order, the Steiner point on edge k is node 8+k, face
points are nodes 20-25 and the body point is node 26, in VTK triquadratic
hexahedron order.  Positions are kept in *unit* coordinates (s, t, u) in
[0, 1]^3, exact rationals; the real point is (s*a, t*b, u*c).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Iterable, Mapping

from ..errors import InputError
from .codes import CUBOID_CODE, digit_parameters, parameter_digits, parse_point_suffix, point_suffix
from .exact import Length, parse_rational

__all__ = [
    "BODY_NODE",
    "BaseConfiguration",
    "Box",
    "CORNERS",
    "Configuration",
    "EDGES",
    "FACES",
    "FACE_POINT_SOURCES",
    "POINT_POLICIES",
    "edge_axis",
    "parse_point_suffix",
    "point_suffix",
]

CORNERS: tuple[tuple[int, int, int], ...] = (
    (0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0),
    (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1),
)
EDGES: tuple[tuple[int, int], ...] = (
    (0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6),
    (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7),
)
# Face k carries node 20+k (VTK triquadratic hexahedron order).
FACES: tuple[tuple[int, int, int, int], ...] = (
    (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7), (0, 1, 2, 3), (4, 5, 6, 7),
)
BODY_NODE = 26
POINT_POLICIES = ("octree", "none")
AXIS_NAMES = "xyz"


def edge_axis(edge: int) -> int:
    """The coordinate axis (0, 1, 2) along which edge ``edge`` runs."""
    p, q = (CORNERS[i] for i in EDGES[edge])
    return next(axis for axis in range(3) if p[axis] != q[axis])


def _face_edges(face: int) -> tuple[int, ...]:
    corners = set(FACES[face])
    return tuple(k for k, (p, q) in enumerate(EDGES) if p in corners and q in corners)


FACE_EDGES = tuple(_face_edges(f) for f in range(6))
EDGE_AXES = tuple(edge_axis(k) for k in range(12))
# Unit coordinates of the corners, and of each edge's lower-coordinate end.
_CORNER_POINTS = tuple(tuple(Fraction(x) for x in corner) for corner in CORNERS)
_EDGE_STARTS = tuple(min((_CORNER_POINTS[i] for i in EDGES[k])) for k in range(12))


@dataclass(frozen=True)
class Box:
    """Edge lengths a, b, c of the cuboid, exact.

    Examples
    --------
    >>> Box.parse(["1", "sqrt(2)", "1.4142"]).texts
    ('1', 'sqrt(2)', '1.4142')
    """

    a: Length
    b: Length
    c: Length

    @classmethod
    def parse(cls, lengths: Iterable) -> "Box":
        values = list(lengths)
        if len(values) != 3:
            raise InputError(f"box {values!r}: needs exactly three lengths A B C")
        return cls(*(Length.parse(v) for v in values))

    @property
    def lengths(self) -> tuple[Length, Length, Length]:
        return (self.a, self.b, self.c)

    @property
    def squared(self) -> tuple[Fraction, Fraction, Fraction]:
        return (self.a.squared, self.b.squared, self.c.squared)

    @property
    def texts(self) -> tuple[str, str, str]:
        return tuple(length.text for length in self.lengths)

    def to_float(self) -> tuple[float, float, float]:
        return tuple(float(length) for length in self.lengths)


def steiner_parameters(steiner: Mapping | Iterable | None, edges: int = 12,
                       element: str = "cuboid") -> tuple[Fraction | None, ...]:
    """The Steiner parameter of each of ``edges`` edges from ``{edge: t}`` or ``[(edge, t), ...]``.

    Edge numbers are ASCII digits (or ints), an edge given twice is refused by value
    (``0`` and ``00`` are one edge, never the last one winning), and every t is an
    exact number strictly between 0 and 1.

    >>> steiner_parameters([("0", "1/2"), ("00", "1/3")])
    Traceback (most recent call last):
    ...
    cospherical.errors.InputError: edge '00': edge 0 is given twice
    """
    params: list[Fraction | None] = [None] * edges
    for edge, value in (steiner.items() if isinstance(steiner, Mapping) else steiner or ()):
        text = str(edge).strip(" \t")
        # isascii: str.isdigit() also accepts digits such as '²' or '٣' that are not ours
        if isinstance(edge, bool) or not isinstance(edge, (int, str)) or not (text.isascii() and text.isdigit()) \
                or int(text) >= edges:
            raise InputError(f"edge {edge!r}: not an edge number 0..{edges - 1}"
                             + ("" if element == "cuboid" else f" of the {element}"))
        k = int(text)
        if params[k] is not None:
            raise InputError(f"edge {edge!r}: edge {k} is given twice")
        t = parse_rational(value, f"Steiner parameter on edge {k}")
        if not 0 < t < 1:
            raise InputError(f"Steiner parameter on edge {k} is {value!r}: must lie strictly between 0 and 1")
        params[k] = t
    return tuple(params)


FACE_POINT_SOURCES = (*POINT_POLICIES, "explicit")


def _face_numbers(faces: Iterable, where: str) -> frozenset[int]:
    numbers = []
    for face in faces:
        text = str(face).strip()
        # isascii: str.isdigit() also accepts digits such as '²' that int() refuses
        if isinstance(face, bool) or not isinstance(face, (int, str)) or not (text.isascii() and text.isdigit()) \
                or int(text) > 5:
            raise InputError(f"{where}: face {face!r}: not a face number 0..5")
        if int(text) in numbers:
            raise InputError(f"{where}: face {int(text)} given twice")
        numbers.append(int(text))
    return frozenset(numbers)


class BaseConfiguration:
    """What every configuration of a base element is, a cuboid's or another shape's.

    It has ``box``, ``steiner`` (a parameter or ``None`` per edge), ``face_points``
    (the policy), ``code`` and ``point_set_code``, ``point_faces`` and
    ``has_body_point``, ``shape`` (``None`` for the cuboid), ``nodes()`` (node id
    -> exact unit coordinates) and ``contains(point)`` (the FVM test); the
    tessellation, the studies and the writers use nothing else.
    """

    def real_nodes(self) -> dict[int, tuple[float, float, float]]:
        """Node id -> float coordinates in the real box (for output and plotting)."""
        scale = self.box.to_float()
        return {i: tuple(float(x) * s for x, s in zip(p, scale)) for i, p in self.nodes().items()}


@dataclass(frozen=True)
class Configuration(BaseConfiguration):
    """A 1-irregular cuboid: a box, at most one Steiner point per edge, and its face and body points.

    ``steiner[k]`` is the parameter t in (0, 1) of the point on edge k (measured
    from the edge's lower-coordinate end), or ``None``.  ``face_points`` says how
    the face points (nodes 20-25) and the body point (node 26) are given: by a
    policy, ``octree`` (the paper's: every admissible face, the body point when
    all six) or ``none``, or ``explicit``: then ``faces`` is the set of faces
    carrying a point and ``body`` whether the body point is there.  A face may
    carry a point only where its four edges are split with opposite edges at the
    same parameter (its point lies where the two cut lines cross); the body
    point needs all six face points (a cuboid refined into eight).

    Examples
    --------
    >>> cfg = Configuration.from_code("800000000000")
    >>> cfg.steiner[0], cfg.code
    (Fraction(1, 2), '800000000000')
    >>> sorted(Configuration.from_code("888888888888").nodes())[-1]
    26
    >>> leaf = Configuration.from_code("888888888888", faces=[0, 4])
    >>> leaf.code, sorted(leaf.nodes())[-2:]
    ('888888888888+f04', [20, 24])
    >>> Configuration.from_code("888888888888").point_set_code
    '888888888888+f012345b'
    """

    box: Box
    steiner: tuple[Fraction | None, ...]
    face_points: str = "octree"
    faces: frozenset[int] | None = None
    body: bool = False

    def __post_init__(self) -> None:
        if len(self.steiner) != 12:
            raise InputError(f"steiner: needs 12 entries, got {len(self.steiner)}")
        if self.face_points not in FACE_POINT_SOURCES:
            raise InputError(f"face-point policy {self.face_points!r}: choose one of {', '.join(POINT_POLICIES)}")
        if (self.faces is not None) != (self.face_points == "explicit"):
            raise InputError("face points: give the set of faces exactly when face_points is 'explicit'")
        if self.body and self.face_points != "explicit":
            raise InputError(f"body point: the {self.face_points} policy decides it; give the faces explicitly")
        if self.faces is None:
            return
        object.__setattr__(self, "faces", _face_numbers(self.faces, "face points"))
        for face in sorted(self.faces):
            reason = self._inadmissible(face)
            if reason:
                corners = " ".join(map(str, FACES[face]))
                raise InputError(f"face {face} (corners {corners}) cannot carry a point: {reason}")
        if self.body and len(self.faces) != 6:
            raise InputError("body point: needs all six face points (a cuboid refined into eight), "
                             f"got faces {', '.join(map(str, sorted(self.faces))) or 'none'}")

    @classmethod
    def from_steiner(
        cls,
        box: Box | Iterable = ("1", "1", "1"),
        steiner: Mapping | Iterable | None = None,
        face_points: str = "octree",
        faces: Iterable | None = None,
        body: bool = False,
    ) -> "Configuration":
        """Build from ``{edge: t}`` or ``[(edge, t), ...]``; t may be a string, int or Fraction.

        ``faces`` (face numbers 0..5) and ``body`` give the face and body points
        explicitly; then ``face_points`` is ignored.
        """
        box = box if isinstance(box, Box) else Box.parse(box)
        return cls._build(box, steiner_parameters(steiner), face_points, faces, body)

    @classmethod
    def from_code(
        cls,
        code: str,
        box: Box | Iterable = ("1", "1", "1"),
        face_points: str = "octree",
        faces: Iterable | None = None,
        body: bool = False,
    ) -> "Configuration":
        """Build from a configuration code: 12 hex digits (digit k: t = n/16 on edge k, 0 = none),
        optionally followed by the point suffix ``+f<faces>[b]``.

        A suffix names every face and body point, whatever ``face_points`` says; a
        bare code takes them from the policy (``octree`` or ``none``), or from
        ``faces`` and ``body``.  ``face_points="explicit"`` asks for a suffix.
        """
        match = CUBOID_CODE.match(code) if isinstance(code, str) else None
        if not match:
            raise InputError(f"configuration code {code!r}: needs exactly 12 hexadecimal digits, "
                             "optionally followed by a point suffix such as +f04")
        box = box if isinstance(box, Box) else Box.parse(box)
        params = digit_parameters(match["edges"])
        if match["suffix"] is not None:
            if faces is not None or body:
                raise InputError(f"configuration code {code!r}: its suffix gives the face points; "
                                 "do not give them again")
            faces, body = parse_point_suffix(code, match["suffix"])
        elif face_points == "explicit" and faces is None:
            raise InputError(f"configuration code {code!r}: needs a point suffix (+f<faces>[b]) "
                             "where the face points are explicit")
        return cls._build(box, params, face_points, faces, body)

    @classmethod
    def _build(cls, box, params, face_points, faces, body) -> "Configuration":
        if faces is not None or body:  # __post_init__ checks and normalises the faces
            return cls(box, params, "explicit", tuple(faces or ()), body)
        return cls(box, params, face_points)

    @property
    def code(self) -> str | None:
        """The configuration code as its own policy reads it: 12 hex digits under ``octree``
        or ``none``, with the point suffix when the points are explicit; ``None`` when some
        t is not a multiple of 1/16."""
        if self.face_points == "explicit":
            return self.point_set_code
        return parameter_digits(self.steiner)

    @property
    def point_set_code(self) -> str | None:
        """The code of the whole point set, the same under every policy (always suffixed)."""
        digits = parameter_digits(self.steiner)
        if digits is None:
            return None
        return f"{digits}+{point_suffix(self.point_faces, self.has_body_point)}"

    @property
    def admissible_faces(self) -> frozenset[int]:
        """The faces that may carry a point: four split edges, opposite ones at the same t."""
        return frozenset(f for f in range(6) if not self._inadmissible(f))

    @property
    def point_faces(self) -> frozenset[int]:
        """The faces carrying a point, under any policy."""
        if self.face_points == "explicit":
            return self.faces
        return self.admissible_faces if self.face_points == "octree" else frozenset()

    @property
    def has_body_point(self) -> bool:
        """Whether node 26 is there: explicit, or under ``octree`` when all six faces carry a point."""
        if self.face_points == "explicit":
            return self.body
        return self.face_points == "octree" and len(self.point_faces) == 6

    def explicit(self) -> "Configuration":
        """The same point set with its face and body points given explicitly."""
        return Configuration(self.box, self.steiner, "explicit", self.point_faces, self.has_body_point)

    def nodes(self) -> dict[int, tuple[Fraction, Fraction, Fraction]]:
        """Node id -> exact unit coordinates (s, t, u), ids in increasing order."""
        nodes = dict(enumerate(_CORNER_POINTS))
        for k, t in enumerate(self.steiner):
            if t is not None:
                start = list(_EDGE_STARTS[k])
                start[EDGE_AXES[k]] = t
                nodes[8 + k] = tuple(start)
        for f in sorted(self.point_faces):
            nodes[20 + f] = self._face_point(f)
        if self.has_body_point:
            nodes[BODY_NODE] = tuple(self._parallel_parameter(axis) for axis in range(3))
        return nodes

    def _parallel_parameter(self, axis: int) -> Fraction:
        return next(t for k, t in enumerate(self.steiner) if EDGE_AXES[k] == axis)

    def _inadmissible(self, face: int) -> str | None:
        """Why face ``face`` cannot carry a point, or ``None`` when it can."""
        edges = FACE_EDGES[face]
        unsplit = [k for k in edges if self.steiner[k] is None]
        if unsplit:
            return f"edge {unsplit[0]} carries no Steiner point"
        for axis in sorted({EDGE_AXES[k] for k in edges}):
            p, q = (k for k in edges if EDGE_AXES[k] == axis)
            if self.steiner[p] != self.steiner[q]:
                return (f"opposite edges {p} and {q} are split at different parameters, "
                        f"{self.steiner[p]} and {self.steiner[q]}")
        return None

    def _face_point(self, face: int) -> tuple[Fraction, Fraction, Fraction]:
        # The face of a refined neighbour, where the two cut lines cross.
        point = list(_CORNER_POINTS[FACES[face][0]])
        for k in FACE_EDGES[face]:
            point[EDGE_AXES[k]] = self.steiner[k]
        return tuple(point)

    @property
    def shape(self) -> None:
        """``None``: the cuboid's numbering is this module's, not a
        :class:`~cospherical.core.shapes.Shape` (whose configurations have one)."""
        return None

    def contains(self, point, closed: bool = True) -> bool:
        """Whether a point (unit coordinates) lies in the closed (or open) box, exactly: the FVM test."""
        if closed:
            return all(0 <= x <= 1 for x in point)
        return all(0 < x < 1 for x in point)
