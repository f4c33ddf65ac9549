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
from .exact import Length, parse_rational

__all__ = [
    "BODY_NODE",
    "Box",
    "CORNERS",
    "Configuration",
    "EDGES",
    "FACES",
    "POINT_POLICIES",
    "edge_axis",
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


def _parse_parameter(edge: int, value) -> Fraction:
    t = parse_rational(value, f"Steiner parameter on edge {edge}")
    if not 0 < t < 1:
        raise InputError(f"Steiner parameter on edge {edge} is {value!r}: must lie strictly between 0 and 1")
    return t


def _parse_edge(edge) -> int:
    text = str(edge).strip()
    # isascii: str.isdigit() also accepts digits such as '²' that int() refuses
    if isinstance(edge, bool) or not isinstance(edge, (int, str)) or not (text.isascii() and text.isdigit()) \
            or int(text) > 11:
        raise InputError(f"edge {edge!r}: not an edge number 0..11")
    return int(text)


@dataclass(frozen=True)
class Configuration:
    """A 1-irregular cuboid: a box, at most one Steiner point per edge, and a point policy.

    ``steiner[k]`` is the parameter t in (0, 1) of the point on edge k (measured
    from the edge's lower-coordinate end), or ``None``.

    Examples
    --------
    >>> cfg = Configuration.from_code("800000000000")
    >>> cfg.steiner[0], cfg.code
    (Fraction(1, 2), '800000000000')
    >>> sorted(Configuration.from_code("888888888888").nodes())[-1]
    26
    """

    box: Box
    steiner: tuple[Fraction | None, ...]
    face_points: str = "octree"

    def __post_init__(self) -> None:
        if len(self.steiner) != 12:
            raise InputError(f"steiner: needs 12 entries, got {len(self.steiner)}")
        if self.face_points not in POINT_POLICIES:
            raise InputError(f"face-point policy {self.face_points!r}: choose one of {', '.join(POINT_POLICIES)}")

    @classmethod
    def from_steiner(
        cls,
        box: Box | Iterable = ("1", "1", "1"),
        steiner: Mapping | None = None,
        face_points: str = "octree",
    ) -> "Configuration":
        """Build from ``{edge: t}``; t may be a string, int or Fraction."""
        box = box if isinstance(box, Box) else Box.parse(box)
        params: list[Fraction | None] = [None] * 12
        for edge, value in (steiner or {}).items():
            k = _parse_edge(edge)
            params[k] = _parse_parameter(k, value)
        return cls(box, tuple(params), face_points)

    @classmethod
    def from_code(
        cls, code: str, box: Box | Iterable = ("1", "1", "1"), face_points: str = "octree"
    ) -> "Configuration":
        """Build from the 12-hex-digit configuration code (digit k: t = n/16 on edge k, 0 = none)."""
        if not isinstance(code, str) or len(code) != 12 or any(ch not in "0123456789abcdefABCDEF" for ch in code):
            raise InputError(f"configuration code {code!r}: needs exactly 12 hexadecimal digits")
        box = box if isinstance(box, Box) else Box.parse(box)
        params = tuple(Fraction(int(ch, 16), 16) if ch != "0" else None for ch in code)
        return cls(box, params, face_points)

    @property
    def code(self) -> str | None:
        """The configuration code, or ``None`` when some t is not a multiple of 1/16."""
        digits = []
        for t in self.steiner:
            if t is None:
                digits.append("0")
            elif (t * 16).denominator == 1:
                digits.append("%x" % int(t * 16))
            else:
                return None
        return "".join(digits)

    def nodes(self) -> dict[int, tuple[Fraction, Fraction, Fraction]]:
        """Node id -> exact unit coordinates (s, t, u), ids in increasing order."""
        nodes = dict(enumerate(_CORNER_POINTS))
        for k, t in enumerate(self.steiner):
            if t is not None:
                start = list(_EDGE_STARTS[k])
                start[EDGE_AXES[k]] = t
                nodes[8 + k] = tuple(start)
        if self.face_points == "octree":
            faces = [self._face_point(f) for f in range(6)]
            for f, point in enumerate(faces):
                if point is not None:
                    nodes[20 + f] = point
            if all(point is not None for point in faces):
                nodes[BODY_NODE] = tuple(self._parallel_parameter(axis) for axis in range(3))
        return nodes

    def _parallel_parameter(self, axis: int) -> Fraction:
        return next(t for k, t in enumerate(self.steiner) if EDGE_AXES[k] == axis)

    def _face_point(self, face: int) -> tuple[Fraction, Fraction, Fraction] | None:
        # The face of a refined neighbour: exists when the four edges are split
        # and opposite edges agree, at the crossing of the two cut lines.
        edges = FACE_EDGES[face]
        if any(self.steiner[k] is None for k in edges):
            return None
        point = list(_CORNER_POINTS[FACES[face][0]])
        for axis in {EDGE_AXES[k] for k in edges}:
            values = {self.steiner[k] for k in edges if EDGE_AXES[k] == axis}
            if len(values) != 1:
                return None
            point[axis] = values.pop()
        return tuple(point)

    def real_nodes(self) -> dict[int, tuple[float, float, float]]:
        """Node id -> float coordinates in the real box (for output and plotting)."""
        scale = self.box.to_float()
        return {i: tuple(float(x) * s for x, s in zip(p, scale)) for i, p in self.nodes().items()}
