"""1-irregular configurations of a base element: its shape, Steiner points, face and body points.

One class for every base element, the cuboid one standard shape among prism,
pyramid and tetrahedron (:mod:`cospherical.core.shapes`; the box and the node
numbering are :mod:`cospherical.core.box`'s: for the cuboid, corners 0-7 in VTK
hexahedron order, the Steiner point on edge k is node 8+k, face points are nodes
20-25 and the body point is node 26, as that module draws them).  Positions are kept in
*unit* coordinates (s, t, u), exact rationals; the real point is (s*a, t*b, u*c).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property
from typing import Iterable, Mapping, Sequence, cast

from ..choices import FACE_POINT_SOURCES, POINT_POLICIES, FacePointSource
from ..errors import InputError, shown
from .codes import digit_parameters, edge_code_pattern, parameter_digits, parse_point_suffix, point_suffix
from .exact import parse_rational
from .geometry import Rational
from .box import Box, Point
from .shapes import Shape, standard_shape

# Box: the type of a configuration's box (Configuration.box), public here with the class that takes it
__all__ = ["Box", "Configuration", "steiner_parameters"]



def steiner_parameters(steiner: Mapping[object, object] | Iterable[tuple[object, object]] | None, edges: int = 12,
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
        k = None if isinstance(edge, bool) or not isinstance(edge, (int, str)) else _index(str(edge).strip(" \t"), edges)
        if k is None:
            raise InputError(f"edge {shown(edge)}: not an edge number 0..{edges - 1}"
                             + ("" if element == "cuboid" else f" of the {element}"))
        if params[k] is not None:
            raise InputError(f"edge {edge!r}: edge {k} is given twice")
        t = parse_rational(value, f"Steiner parameter on edge {k}")
        if not 0 < t < 1:
            raise InputError(f"Steiner parameter on edge {k} is {value!r}: must lie strictly between 0 and 1")
        params[k] = t
    return tuple(params)


def _face_numbers(faces: Iterable[object], shape: Shape, where: str) -> frozenset[int]:
    numbers = []
    last = len(shape.faces) - 1
    for face in faces:
        number = None if isinstance(face, bool) or not isinstance(face, (int, str)) else _index(str(face).strip(), last + 1)
        if number is None:
            raise InputError(f"{where}: face {shown(face)}: not a face number 0..{last}"
                             + ("" if shape.name == "cuboid" else f" of the {shape.name}"))
        if number in numbers:
            raise InputError(f"{where}: face {number} given twice")
        numbers.append(number)
    return frozenset(numbers)


def _index(text: str, count: int) -> int | None:
    """The number 0..count-1 that ``text`` writes in ASCII digits, else None.

    isascii: str.isdigit() also accepts digits such as '²' or '٣' that are not ours; the length is
    bounded before int(), which refuses over 4,300 digits with a ValueError of its own.

    >>> _index("007", 12), _index("12", 12), _index("9" * 5000, 12), _index("\u0663", 12)
    (7, None, None, None)
    """
    digits = text.lstrip("0") or "0"
    if not (text.isascii() and text.isdigit()) or len(digits) > len(str(count)):
        return None
    return int(digits) if int(digits) < count else None



def _shape(shape: Shape | None, box: Box | Iterable[str | int | Fraction] | None) -> Shape:
    """The base element of a constructor: ``shape``, or the cuboid in ``box`` (default the cube)."""
    if shape is None:
        return standard_shape("cuboid", ("1", "1", "1") if box is None else box)
    if box is not None:
        raise InputError("configuration: give the box or the shape (which has its box), not both")
    return shape


@dataclass(frozen=True)
class Configuration:
    """A 1-irregular base element: its shape, at most one Steiner point per edge, and its face and body points.

    ``shape`` is the base element in its box (:func:`~cospherical.core.shapes.standard_shape`:
    the cuboid, a prism, a pyramid, a tetrahedron; or any convex
    :class:`~cospherical.core.shapes.Shape`).  ``steiner[k]`` is the parameter t in (0, 1)
    of the point on edge k (measured from the edge's lower end), or ``None``.
    ``face_points`` says how the face points and the body point are given: by a policy,
    ``octree`` (the paper's: every admissible face, and the body point of a parallelepiped
    when all six) or ``none``, or ``explicit``: then ``faces`` is the set of faces carrying a
    point and ``body`` whether the body point is there.  A face may carry a point only where
    it is a quadrilateral whose four edges are split with opposite edges at the same
    parameter (its point lies where the two cut lines cross); the body point needs a point on
    every face of a parallelepiped (a cuboid refined into eight).

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
    >>> pyramid = Configuration.from_code("88880000", shape=standard_shape("pyramid"))
    >>> sorted(pyramid.nodes())[-1], pyramid.point_faces
    (13, frozenset({0}))
    """

    shape: Shape
    steiner: tuple[Fraction | None, ...]
    face_points: FacePointSource = "octree"
    faces: frozenset[int] | None = None
    body: bool = False

    def __post_init__(self) -> None:
        shape = self.shape
        if len(self.steiner) != len(shape.edges):
            raise InputError(f"steiner: needs {len(shape.edges)} entries, got {len(self.steiner)}")
        if self.face_points not in FACE_POINT_SOURCES:
            raise InputError(f"face-point policy {self.face_points!r}: choose one of {', '.join(POINT_POLICIES)}")
        if (self.faces is not None) != (self.face_points == "explicit"):
            raise InputError("face points: give the set of faces exactly when face_points is 'explicit'")
        if self.body and self.face_points != "explicit":
            raise InputError(f"body point: the {self.face_points} policy decides it; give the faces explicitly")
        if self.faces is None:
            return
        object.__setattr__(self, "faces", _face_numbers(self.faces, shape, "face points"))
        for face in sorted(self.faces):
            reason = self._inadmissible(face)
            if reason:
                corners = " ".join(map(str, shape.faces[face]))
                raise InputError(f"face {face} (corners {corners}) cannot carry a point: {reason}")
        if self.body:
            if shape.body_node is None:
                raise InputError(f"body point: the {shape.name} has none (only a parallelepiped, refined into "
                                 "eight, has one)")
            if len(self.faces) != len(shape.faces):
                raise InputError("body point: needs all six face points (a cuboid refined into eight), "
                                 f"got faces {', '.join(map(str, sorted(self.faces))) or 'none'}")

    @classmethod
    def from_steiner(
        cls,
        box: Box | Iterable[str | int | Fraction] | None = None,
        steiner: Mapping[object, object] | Iterable[tuple[object, object]] | None = None,
        face_points: FacePointSource = "octree",
        faces: Iterable[object] | None = None,
        body: bool = False,
        shape: Shape | None = None,
    ) -> "Configuration":
        """Build from ``{edge: t}`` or ``[(edge, t), ...]``; t may be a string, int or Fraction.

        The element is ``shape``, or the cuboid in ``box`` (default the cube).  ``faces``
        (face numbers) and ``body`` give the face and body points explicitly; then
        ``face_points`` is ignored.
        """
        shape = _shape(shape, box)
        return cls._build(shape, steiner_parameters(steiner, len(shape.edges), shape.name), face_points, faces, body)

    @classmethod
    def from_code(
        cls,
        code: str,
        box: Box | Iterable[str | int | Fraction] | None = None,
        face_points: FacePointSource = "octree",
        faces: Iterable[object] | None = None,
        body: bool = False,
        shape: Shape | None = None,
    ) -> "Configuration":
        """Build from a configuration code: one hexadecimal digit per edge (digit n: t = n/16 on
        that edge, 0 = none; 12 for the cuboid), optionally followed by the point suffix
        ``+f<faces>[b]``.

        The element is ``shape``, or the cuboid in ``box`` (default the cube).  A suffix
        names every face and body point, whatever ``face_points`` says; a bare code takes
        them from the policy (``octree`` or ``none``), or from ``faces`` and ``body``.
        ``face_points="explicit"`` asks for a suffix.
        """
        shape = _shape(shape, box)
        count = len(shape.edges)
        match = edge_code_pattern(count).match(code) if isinstance(code, str) else None
        if not match:
            raise InputError(f"configuration code {code!r}: "
                             + ("needs exactly 12 hexadecimal digits" if shape.name == "cuboid" else
                                f"the {shape.name} needs exactly {count} hexadecimal digits, one per edge")
                             + ", optionally followed by a point suffix such as +f04")
        params = digit_parameters(match["edges"])
        if match["suffix"] is not None:
            if faces is not None or body:
                raise InputError(f"configuration code {code!r}: its suffix gives the face points; "
                                 "do not give them again")
            faces, body = parse_point_suffix(code, match["suffix"])
        elif face_points == "explicit" and faces is None:
            raise InputError(f"configuration code {code!r}: needs a point suffix (+f<faces>[b]) "
                             "where the face points are explicit")
        return cls._build(shape, params, face_points, faces, body)

    @classmethod
    def _build(cls, shape: Shape, params: tuple[Fraction | None, ...], face_points: FacePointSource,
               faces: Iterable[object] | None, body: bool) -> "Configuration":
        if faces is not None or body:  # __post_init__ checks and normalises the faces
            return cls(shape, params, "explicit", cast("frozenset[int]", tuple(faces or ())), body)
        return cls(shape, params, face_points)

    @property
    def box(self) -> Box:
        return self.shape.box

    @property
    def code(self) -> str | None:
        """The configuration code as its own policy reads it: the edge digits under ``octree``
        or ``none``, with the point suffix when the points are explicit; ``None`` when some
        t is not a multiple of 1/16."""
        if self.face_points == "explicit":
            return self.point_set_code
        return parameter_digits(self.steiner)

    @cached_property  # asked for by the table look-up, the assembly and the statistics: its digits are Fractions'
    def point_set_code(self) -> str | None:
        """The code of the whole point set, the same under every policy (always suffixed;
        ``None`` as :attr:`code`, or where a face number has more than one digit)."""
        digits = parameter_digits(self.steiner)
        if digits is None or any(f > 9 for f in self.point_faces):
            return None
        return f"{digits}+{point_suffix(self.point_faces, self.has_body_point)}"

    @cached_property
    def admissible_faces(self) -> frozenset[int]:
        """The faces that may carry a point: quadrilaterals with four split edges, opposite ones at the same t."""
        return frozenset(self._face_cuts)

    @cached_property
    def _face_cuts(self) -> dict[int, tuple[Fraction, Fraction]]:
        # Admissible face -> the parameters (t along c0->c1, s along c0->c3) of its cut lines.
        cuts = {}
        steiner = self.steiner
        for f, ((a, fa), (b, fb), (c, fc), (d, fd)) in self.shape.cut_sides.items():
            ta, tb, tc, td = steiner[a], steiner[b], steiner[c], steiner[d]
            if ta is None or tb is None or tc is None or td is None:
                continue
            # opposite sides at one parameter, measured the same way (one of them reversed: 1 - t)
            if (ta == tb if fa == fb else ta == 1 - tb) and (tc == td if fc == fd else tc == 1 - td):
                cuts[f] = (ta if fa else 1 - ta, tc if fc else 1 - tc)
        return cuts

    @property
    def point_faces(self) -> frozenset[int]:
        """The faces carrying a point, under any policy."""
        if self.faces is not None:  # exactly when the points are explicit
            return self.faces
        return self.admissible_faces if self.face_points == "octree" else frozenset()

    @property
    def has_body_point(self) -> bool:
        """Whether the body point is there: explicit, or under ``octree`` when every face of a
        parallelepiped carries a point."""
        if self.face_points == "explicit":
            return self.body
        return (self.face_points == "octree" and self.shape.body_node is not None
                and len(self.point_faces) == len(self.shape.faces))

    def explicit(self) -> "Configuration":
        """The same point set with its face and body points given explicitly."""
        return Configuration(self.shape, self.steiner, "explicit", self.point_faces, self.has_body_point)

    def nodes(self) -> dict[int, Point]:
        """Node id -> exact unit coordinates (s, t, u), ids in increasing order."""
        shape = self.shape
        nodes = dict(enumerate(shape.corners))
        first = len(shape.corners)
        for k, t in enumerate(self.steiner):
            if t is not None:
                nodes[first + k] = shape.edge_point(k, t)
        for f in sorted(self.point_faces):  # each admissible: explicit faces are checked on construction
            nodes[shape.face_nodes[f]] = shape.face_point(f, *self._face_cuts[f])
        if self.has_body_point:
            # every face carries a point, so all the edges of a parallel class are split at one t
            origin, classes = cast("tuple[int, tuple[tuple[tuple[Rational, ...], tuple[int, ...]], ...]]",
                                   shape.parallelepiped)
            point: Sequence[Rational] = shape.corners[origin]
            for d, edges in classes:
                t = cast(Fraction, self.steiner[edges[0]])
                point = tuple(x + t * y if y else x for x, y in zip(point, d))
            nodes[cast(int, shape.body_node)] = (point[0], point[1], point[2])
        return nodes

    def real_nodes(self) -> dict[int, tuple[float, float, float]]:
        """Node id -> float coordinates in the real box (for output and plotting)."""
        scale = self.box.to_float()
        return {i: (float(p[0]) * scale[0], float(p[1]) * scale[1], float(p[2]) * scale[2])
                for i, p in self.nodes().items()}

    def _cut_parameters(self, f: int) -> list[Fraction]:
        # the parameters on the sides of Shape.cut_sides, each measured the way its side runs
        # every side is split: the caller asked first
        steiner = cast("tuple[Fraction, ...]", self.steiner)
        return [steiner[k] if forward else 1 - steiner[k] for k, forward in self.shape.cut_sides[f]]

    def _inadmissible(self, face: int) -> str | None:
        """Why face ``face`` cannot carry a point, or ``None`` when it can."""
        sides = self.shape.cut_sides.get(face)
        if sides is None:
            return f"it has {len(self.shape.faces[face])} corners: only a quadrilateral face carries a point"
        unsplit = sorted(k for k, _ in sides if self.steiner[k] is None)
        if unsplit:
            return f"edge {unsplit[0]} carries no Steiner point"
        params = self._cut_parameters(face)
        for i in sorted((0, 2), key=lambda i: min(sides[i][0], sides[i + 1][0])):  # the pair of the lowest edge first
            if params[i] != params[i + 1]:
                p, q = sorted((sides[i][0], sides[i + 1][0]))
                return (f"opposite edges {p} and {q} are split at different parameters, "
                        f"{self.steiner[p]} and {self.steiner[q]}")
        return None

    def contains(self, point: Sequence[Rational], closed: bool = True) -> bool:
        """Whether a point (unit coordinates) lies in the closed (or open) base element, exactly: the FVM test."""
        return self.shape.contains(point, closed)
