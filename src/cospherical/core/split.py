"""Splits of an element into smaller co-spherical elements (paper, section 4.2).

A split cuts a convex element into pieces with no new vertex, and never cuts
one of its boundary faces.  Two criteria:

``internal_faces``
    every edge of every piece is an edge of the element: new faces are spanned
    by existing edges (a bipyramid's equator, for instance);
``internal_edges_and_faces``
    a piece may also have an edge through the element's interior, never one
    lying on a boundary face.

The vertices of an element are co-spherical, so every piece is again a
Delaunay element with the same circumsphere.  The search grows a subdivision
face to face from the first boundary face, as :mod:`cospherical.core.delaunay` does:
the piece across an open face is the hull of the face and of some vertices
beyond it.  Each subdivision is found exactly once; it is complete when no
face is open and the pieces' volumes add up to the element's (a closed
face-to-face complex with the element's boundary and its volume covers the
element exactly once).
"""

from __future__ import annotations

from itertools import combinations
from typing import Sequence

from ..choices import SPLIT_CRITERIA, SplitCriterion
from ..errors import InputError
from .delaunay import hull_faces
from .geometry import Frame, dot, plane_normal, six_volume
from .polyhedron import Polyhedron, face_kind

_Vector = tuple[int, int, int]
# A face of a piece: its cycle (frame indices), its normal, the element's face it lies in (None: inside).
_PieceFace = tuple[tuple[int, ...], _Vector, int | None]
# An allowed piece: its faces and six times its volume (frame units).
_Piece = tuple[list[_PieceFace], int]
# The faces a split has left open: point set -> (cycle, normal pointing into the uncovered part).
_OpenFaces = dict[frozenset[int], tuple[tuple[int, ...], Sequence[int]]]

__all__ = ["subdivisions"]



class _Element:
    """An element in frame indices, with what the criteria need to know about it."""

    def __init__(self, frame: Frame, poly: Polyhedron, criterion: SplitCriterion) -> None:
        if criterion not in SPLIT_CRITERIA:
            raise InputError(f"criterion {criterion!r}: choose one of {', '.join(SPLIT_CRITERIA)}")
        self.frame = frame
        self.poly = poly
        self.criterion = criterion
        index = {node: i for i, node in enumerate(frame.ids)}
        self.members = sorted(index[n] for n in poly.nodes)
        self.faces = [tuple(index[n] for n in face) for face in poly.faces]
        self.face_sets = [frozenset(face) for face in self.faces]
        coords = frame.coords
        self.planes = []
        for face in self.faces:
            normal = plane_normal(coords[face[0]], coords[face[1]], coords[face[2]])
            self.planes.append((normal, dot(normal, coords[face[0]])))
        # The boundary face of every three of its vertices: a hull face lies on a
        # boundary plane exactly when its first three points are on that face (three
        # points of a face span its plane; the element's vertices on a face plane are
        # that face's vertices).
        self.face_of_triple: dict[tuple[int, ...], int] = {triple: f for f, face in enumerate(self.faces)
                               for triple in combinations(sorted(face), 3)}
        self.edges = {frozenset((f[i], f[(i + 1) % len(f)])) for f in self.faces for i in range(len(f))}
        # Ordered pairs (both ways round) that may be an edge of a piece.
        self.allowed = {(v, w) for v in self.members for w in self.members
                        if v != w and self._edge_allowed(frozenset((v, w)))}
        self.points = [(m, *coords[m]) for m in self.members]
        self.six_volume = six_volume(coords, self.faces)
        self._pieces: dict[frozenset[int], _Piece | None] = {}

    def _on_boundary_plane(self, cycle: Sequence[int]) -> int | None:
        return self.face_of_triple.get(tuple(sorted(cycle[:3])))

    def _cuts_boundary(self, points: frozenset[int]) -> bool:
        """Whether the hull of ``points`` would have a face inside a boundary face, decided
        before building the hull (about half of the candidates a search meets).

        The element lies on one side of each boundary plane, so three or more of
        the points on it span a face of the hull there; no three vertices are
        collinear (they lie on a sphere), so that face is the whole boundary face
        only if every vertex of it is among the points (the test of :meth:`_check`).
        """
        for face in self.face_sets:
            shared = len(points & face)
            if 3 <= shared < len(face):
                return True
        return False

    def _edge_allowed(self, edge: frozenset[int]) -> bool:
        if edge in self.edges:
            return True
        if self.criterion == "internal_faces":
            return False
        # An inner edge must pass through the interior: its ends share no face.
        return not any(edge <= face for face in self.face_sets)

    def piece(self, points: frozenset[int]) -> _Piece | None:
        """(faces with their kind of contact, 6 x volume) of the hull of ``points``, or None if not allowed."""
        if points in self._pieces:
            return self._pieces[points]
        result = None
        if not self._cuts_boundary(points):
            try:
                faces = hull_faces(self.frame, sorted(points))
            except ValueError:  # coplanar points span no piece
                faces = None
            if faces is not None:
                result = self._check(faces)
        self._pieces[points] = result
        return result

    def _check(self, faces: list[tuple[tuple[int, ...], _Vector]]) -> _Piece | None:
        checked: list[_PieceFace] = []
        allowed = self.allowed
        for cycle, normal in faces:
            boundary = self._on_boundary_plane(cycle)
            if boundary is not None and len(cycle) != len(self.faces[boundary]):
                return None  # part of a boundary face: the face would be cut
            if any((v, w) not in allowed for v, w in zip(cycle, cycle[1:] + cycle[:1])):
                return None
            checked.append((cycle, normal, boundary))
        return checked, six_volume(self.frame.coords, [c for c, _, _ in checked])

    def beyond(self, cycle: Sequence[int], normal: Sequence[int]) -> list[int]:
        nx, ny, nz = normal
        offset = dot(normal, self.frame.coords[cycle[0]])
        return [m for m, x, y, z in self.points if nx * x + ny * y + nz * z > offset]


def subdivisions(frame: Frame, poly: Polyhedron, criterion: SplitCriterion, limit: int = 200_000) -> list[tuple[Polyhedron, ...]]:
    """Every split of ``poly`` allowed by ``criterion``, the element itself included.

    Each split is a tuple of pieces sorted by node ids; splits come in a fixed order.
    """
    if len(poly.nodes) == 4:  # a tetrahedron has no split without new vertices
        return [(poly,)]
    element = _Element(frame, poly, criterion)
    found: list[tuple[frozenset[int], ...]] = []

    def grow(pieces: list[frozenset[int]], open_faces: _OpenFaces, volume: int, covered: frozenset[int]) -> None:
        if len(found) >= limit:
            raise RuntimeError(f"more than {limit} splits: the search was stopped")
        if not open_faces:
            if volume == element.six_volume and len(covered) == len(element.faces):
                found.append(tuple(sorted(pieces, key=sorted)))
            return
        key = min(open_faces, key=sorted)
        cycle, normal = open_faces[key]
        far = element.beyond(cycle, normal)
        for size in range(1, len(far) + 1):
            for extra in combinations(far, size):
                points = key | frozenset(extra)
                _try(points, pieces, open_faces, volume, covered)

    def _try(points: frozenset[int], pieces: list[frozenset[int]], open_faces: _OpenFaces, volume: int,
             covered: frozenset[int]) -> None:
        piece = element.piece(points)
        if piece is None or points in pieces:
            return
        faces, six = piece
        if volume + six > element.six_volume:
            return
        still_open = dict(open_faces)
        now_covered = set(covered)
        for cycle, normal, boundary in faces:
            key = frozenset(cycle)
            if boundary is not None:
                if boundary in now_covered:
                    return
                now_covered.add(boundary)
            elif key in still_open:
                del still_open[key]  # matched face to face with the piece beyond
            else:
                still_open[key] = (cycle, normal)
        grow(pieces + [points], still_open, volume + six, frozenset(now_covered))

    first = element.faces[0]
    first_normal = tuple(-x for x in element.planes[0][0])  # the element lies beyond its face, inward
    for size in range(1, len(element.members) - len(first) + 1):
        for extra in combinations(element.beyond(first, first_normal), size):
            _try(frozenset(first) | frozenset(extra), [], {}, 0, frozenset())
    made: dict[frozenset[int], Polyhedron] = {}  # a piece recurs in many splits: measured and built once
    for split in found:
        for points in split:
            if points not in made:
                made[points] = _piece(element, points)
    return [tuple(made[points] for points in split) for split in found]


def _piece(element: _Element, points: frozenset[int]) -> Polyhedron:
    frame, poly = element.frame, element.poly
    piece = element.piece(points)
    assert piece is not None, "a piece of a split is allowed"
    faces = sorted(piece[0], key=lambda face: face[0])
    six = piece[1]
    return Polyhedron(
        nodes=tuple(frame.ids[i] for i in sorted(points)),
        faces=tuple(tuple(frame.ids[i] for i in cycle) for cycle, _, _ in faces),
        # a piece's face on the boundary is the element's face there, of the same kind
        face_kinds=tuple(face_kind(frame, cycle) if boundary is None else poly.face_kinds[boundary]
                         for cycle, _, boundary in faces),
        unit_volume=poly.unit_volume * six / element.six_volume,
        center=poly.center,  # every piece lies on the element's sphere
    )
