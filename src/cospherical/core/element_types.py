"""Element types: canonical code, short stable id, standard name, reference node order."""

from __future__ import annotations

import hashlib
from collections import Counter
from dataclasses import dataclass
from typing import Callable, Iterator, Sequence

from ..caches import cached
from .canonical import canonical_form
from .polyhedron import Polyhedron

# An element's faces: node cycles, counter-clockwise seen from outside.
_Faces = Sequence[Sequence[int]]

__all__ = ["ElementType", "classify", "classify_faces", "element_type", "face_summary", "systematic_name"]

# Names are in Title Case, as the paper names its classes ("Quadrilateral Pyramid").
_POLYGON_ADJECTIVE = {3: "Triangular", 4: "Quadrilateral", 5: "Pentagonal", 6: "Hexagonal", 7: "Heptagonal", 8: "Octagonal"}
_KIND_PLURAL = {
    "triangle": "triangles",
    "rectangle": "rectangles",
    "quadrilateral": "quadrilaterals",
    "pentagon": "pentagons",
    "hexagon": "hexagons",
    "heptagon": "heptagons",
    "octagon": "octagons",
}


@dataclass(frozen=True)
class ElementType:
    """One element type: polyhedra whose labelled face graphs are isomorphic.

    ``name`` is ``structural`` (Tetrahedron, n-gonal Pyramid or Bipyramid,
    Triangular Prism, Cuboid) when the face structure has one, else a systematic
    name from the face counts.  It depends on the polyhedron alone; the catalogue
    (:func:`cospherical.catalogue.type_name`) adds the names of the types it knows.
    ``face_kinds`` counts faces per kind, e.g. ``(("rectangle", 1), ("triangle", 4))``.
    ``vtk`` names the VTK cell type when the type has one (its nodes then follow
    VTK order), else ``None``.
    """

    code: str
    id: str
    name: str
    structural: str | None
    vertices: int
    edges: int
    faces: int
    face_kinds: tuple[tuple[str, int], ...]
    vtk: str | None

    @property
    def face_summary(self) -> str:
        """``4 triangles + 1 rectangle``."""
        return face_summary(dict(self.face_kinds))


def face_summary(face_kinds: dict[str, int]) -> str:
    """Face counts in words, most frequent first: ``4 triangles + 1 rectangle``."""
    parts = []
    for kind, count in sorted(face_kinds.items(), key=lambda kc: (-kc[1], kc[0])):
        parts.append(f"{count} {kind if count == 1 else _KIND_PLURAL.get(kind, kind + 's')}")
    return " + ".join(parts)


def type_id(code: str, vertices: int, faces: int) -> str:
    """Short stable id: size plus the first hex digits of the code's SHA-256."""
    return f"v{vertices}f{faces}-{hashlib.sha256(code.encode()).hexdigest()[:6]}"


def _adjacency(faces: _Faces) -> dict[int, set[int]]:
    adjacent: dict[int, set[int]] = {}
    for face in faces:
        for i, v in enumerate(face):
            w = face[(i + 1) % len(face)]
            adjacent.setdefault(v, set()).add(w)
            adjacent.setdefault(w, set()).add(v)
    return adjacent


def _is_bipyramid(faces: _Faces, kinds: Sequence[str]) -> bool:
    if any(kind != "triangle" for kind in kinds):
        return False
    adjacent = _adjacency(faces)
    ring = len(adjacent) - 2
    apexes = [v for v, ws in adjacent.items() if len(ws) == ring]
    return ring >= 3 and any(
        u not in adjacent[v] and len(adjacent[u] | adjacent[v]) == ring
        for i, u in enumerate(apexes)
        for v in apexes[i + 1 :]
    )


def _standard(faces: _Faces, kinds: Sequence[str]) -> tuple[str | None, str | None]:
    """(name, VTK cell type) where the face structure has a standard one."""
    counts = Counter(kinds)
    vertices = len({v for f in faces for v in f})
    polygons = [kind for kind in kinds if kind != "triangle"]
    if vertices == 4:
        return "Tetrahedron", "tetra"
    if len(polygons) == 1 and len(faces) == vertices:
        base = next(face for face, kind in zip(faces, kinds) if kind != "triangle")
        if len(base) == 4:
            return f"{'Rectangular' if polygons[0] == 'rectangle' else 'Quadrilateral'} Pyramid", "pyramid"
        return f"{_POLYGON_ADJECTIVE.get(len(base), f'{len(base)}-gonal')} Pyramid", None
    if vertices == 6 and counts["triangle"] == 2 and len(faces) == 5:
        return ("Triangular Prism" if counts["rectangle"] == 3 else None), "wedge"
    if vertices == 8 and len(faces) == 6 and all(len(face) == 4 for face in faces):
        return ("Cuboid" if counts["rectangle"] == 6 else None), "hexahedron"
    if _is_bipyramid(faces, kinds):
        return f"{_POLYGON_ADJECTIVE.get(vertices - 2, f'{vertices - 2}-gonal')} Bipyramid", None
    return None, None


def element_type(code: str, faces: _Faces, kinds: Sequence[str]) -> ElementType:
    """The element type of a canonical code (faces and kinds of any member).

    No registry of types is kept (one would only grow in a long-running process): a type is a
    frozen dataclass, compared and hashed by its fields, so two built from one code are equal
    and interchangeable; the bounded classification caches below share the objects they keep.
    """
    vertices = len({v for f in faces for v in f})
    edges = sum(len(f) for f in faces) // 2
    structural, vtk = _standard(faces, kinds)
    face_kinds = tuple(sorted(Counter(kinds).items()))
    name = structural or systematic_name(vertices, face_summary(dict(face_kinds)))
    return ElementType(code, type_id(code, vertices, len(faces)), name, structural, vertices, edges, len(faces),
                       face_kinds, vtk)


def systematic_name(vertices: int, face_summary: str) -> str:
    return f"{vertices}-Vertex Polyhedron ({face_summary})"


def _vtk_order(vtk: str, faces: _Faces, kinds: Sequence[str]) -> tuple[int, ...]:
    """Nodes in VTK order (the first face's right-hand normal points into the cell).

    Of the orderings VTK allows, the smallest tuple of node ids is taken, so a
    plain box lists its corners as 0..7.
    """
    adjacent = _adjacency(faces)

    def orderings(face: Sequence[int], top: Callable[[list[int]], list[int]]) -> Iterator[tuple[int, ...]]:
        cycle = list(reversed(face))  # counter-clockwise from outside, reversed: normal inward
        for i in range(len(cycle)):
            bottom = cycle[i:] + cycle[:i]
            yield (*bottom, *top(bottom))

    def opposite(bottom: list[int]) -> list[int]:
        return [next(w for w in adjacent[v] if w not in bottom) for v in bottom]

    candidates: Iterator[tuple[int, ...]]
    if vtk == "tetra":
        candidates = (o for f in faces for o in orderings(f, lambda b: [v for v in adjacent if v not in b]))
    elif vtk == "pyramid":
        base = next(face for face, kind in zip(faces, kinds) if kind != "triangle")
        candidates = orderings(base, lambda b: [v for v in adjacent if v not in b])
    elif vtk == "wedge":
        candidates = (o for f in faces if len(f) == 3 for o in orderings(f, opposite))
    else:  # hexahedron
        candidates = (o for f in faces for o in orderings(f, opposite))
    return min(candidates)


def classify(poly: Polyhedron) -> tuple[ElementType, tuple[int, ...], bool]:
    """The element type of a polyhedron, its nodes in the type's reference order, and
    whether it is the mirror image of the type's direct form (never for VTK types,
    whose node order is fixed by orientation)."""
    return _classify(poly.faces, poly.face_kinds)


def classify_faces(faces: tuple[tuple[int, ...], ...], kinds: tuple[str, ...]
                   ) -> tuple[ElementType, tuple[int, ...], bool]:
    """:func:`classify` from a polyhedron's face cycles (counter-clockwise from outside) and face kinds."""
    return _classify(faces, kinds)


# A study meets the same cell (same node ids and faces) in many configurations.
@cached(maxsize=1 << 16)
def _classify(faces: tuple[tuple[int, ...], ...], kinds: tuple[str, ...]) -> tuple[ElementType, tuple[int, ...], bool]:
    # The classification only compares node ids, never reads their values, so
    # it is computed on the ids' ranks and mapped back: cells with other ids in
    # the same order (the same shape elsewhere in the box, or in another
    # configuration) share one canonical form, the costly part of a study's
    # pipeline (868 distinct cells but 222 rank patterns in the cube bisection study).
    ids = sorted({v for face in faces for v in face})
    rank = {v: i for i, v in enumerate(ids)}
    etype, order, mirrored = _classify_ranks(tuple(tuple(rank[v] for v in face) for face in faces), kinds)
    return etype, tuple(ids[i] for i in order), mirrored


@cached(maxsize=1 << 16)
def _classify_ranks(faces: tuple[tuple[int, ...], ...], kinds: tuple[str, ...]
                    ) -> tuple[ElementType, tuple[int, ...], bool]:
    form = canonical_form(faces, kinds)
    etype = element_type(form.code, faces, kinds)
    if etype.vtk is None:
        return etype, form.order, form.mirrored
    return etype, _vtk_order(etype.vtk, faces, kinds), False
