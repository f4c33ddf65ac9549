"""The box that scales every base element, and the cuboid's node numbering (VTK's).

A base element's points are kept in *unit* coordinates (s, t, u) (:data:`Point`);
the box A x B x C (:class:`Box`, exact lengths) makes the real point (s*A, t*B, u*C).
The cuboid's numbering, which every part and file format shares: corners 0-7
(VTK hexahedron, :data:`CORNERS`), the Steiner point of edge k (:data:`EDGES`, VTK's
quadratic hexahedron order) is node 8 + k, the point of face f (:data:`FACES`:
20 y=0, 21 x=a, 22 y=b, 23 x=0, 24 z=0, 25 z=c) node 20 + f, the body point node
26.  Nodes 0-19 and 24-26 are where VTK's triquadratic hexahedron has them; its
nodes 20-23 run x=0, x=a, y=0, y=b instead: VTK's 20, 21, 22, 23 are our 23,
21, 20, 22::

            7 ------ 14 ------ 6
           /|                 /|
         15 |      25       13 |
         /  19          22  /  18
        4 ------ 12 ------ 5   |
        |   |              |   |
       16 23|      20     17 21|
        |   3 ------ 10 ---|-- 2
        |  /      24       |  /
        | 11               | 9          z
        |/                 |/           |  y
        0 ------- 8 ------ 1            |/__ x
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Iterable

from ..errors import InputError
from .exact import Length
from .geometry import Rational

__all__ = ["Box", "CORNERS", "EDGES", "FACES", "FACE_EDGES", "Point", "edge_axis"]

Point = tuple[Rational, Rational, Rational]
"""Exact unit coordinates (s, t, u): integers where they are whole, Fractions elsewhere."""


@dataclass(frozen=True)
class Box:
    """Edge lengths a, b, c of the box that scales a base element, exact.

    Examples
    --------
    >>> Box.parse(["1", "sqrt(2)", "1.4142"]).texts
    ('1', 'sqrt(2)', '1.4142')
    """

    a: Length
    b: Length
    c: Length

    @classmethod
    def parse(cls, lengths: Iterable[str | int | Fraction]) -> "Box":
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
        return (self.a.text, self.b.text, self.c.text)

    def to_float(self) -> tuple[float, float, float]:
        return (float(self.a), float(self.b), float(self.c))


# The cuboid's numbering (VTK hexahedron), shared by every part and file format.
CORNERS: tuple[tuple[int, int, int], ...] = (
    (0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0),
    (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1),
)
EDGES: tuple[tuple[int, int], ...] = (
    (0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6),
    (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7),
)
# Face k carries node 20+k, around the box (y=0, x=a, y=b, x=0), then bottom and top.
FACES: tuple[tuple[int, int, int, int], ...] = (
    (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7), (0, 1, 2, 3), (4, 5, 6, 7),
)


def edge_axis(edge: int) -> int:
    """The coordinate axis (0, 1, 2) along which the cuboid's edge ``edge`` runs.

    >>> [edge_axis(k) for k in (0, 1, 8)]
    [0, 1, 2]
    """
    p, q = (CORNERS[i] for i in EDGES[edge])
    return next(axis for axis in range(3) if p[axis] != q[axis])


FACE_EDGES = tuple(tuple(k for k, (p, q) in enumerate(EDGES) if {p, q} <= set(face)) for face in FACES)
"""Per face of the cuboid, its four edges (increasing)."""
