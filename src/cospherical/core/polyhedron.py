"""Polyhedra: a Delaunay cell with its face kinds, edges, volume and circumcenter."""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Iterable

from .delaunay import Cell, hull_faces
from .geometry import Frame, Rational, Sphere, six_volume

__all__ = ["FACE_KINDS", "Measured", "Polyhedron", "face_kind", "measure", "polyhedron"]

# Face labels of the canonical code; a four-gon is a rectangle only with four
# exact right angles, otherwise a quadrilateral.
FACE_KINDS = {3: "triangle", 4: "quadrilateral", 5: "pentagon", 6: "hexagon", 7: "heptagon", 8: "octagon"}


def face_kind(frame: Frame, cycle: tuple[int, ...]) -> str:
    """``triangle``, ``rectangle``, ``quadrilateral``, ``pentagon``, ... (frame indices)."""
    n = len(cycle)
    if n == 4:
        if frame.right_angled(cycle):
            return "rectangle"
    return FACE_KINDS.get(n, f"{n}-gon")


@dataclass(frozen=True)
class Polyhedron:
    """A convex polyhedron of the tessellation, exact.

    ``faces`` are node-id cycles counter-clockwise seen from outside, with
    ``face_kinds`` in the same order; ``unit_volume`` is the fraction of the box
    volume; ``center`` the circumcenter in exact unit coordinates.
    """

    nodes: tuple[int, ...]
    faces: tuple[tuple[int, ...], ...]
    face_kinds: tuple[str, ...]
    unit_volume: Fraction
    center: tuple[Rational, Rational, Rational]

    @property
    def edges(self) -> tuple[tuple[int, int], ...]:
        pairs = {(a, b) if a < b else (b, a) for f in self.faces for a, b in zip(f, f[1:] + f[:1])}
        return tuple(sorted(pairs))

    @property
    def counts(self) -> tuple[int, int, int]:
        """(vertices, edges, faces)."""
        return len(self.nodes), len(self.edges), len(self.faces)

    def center_in_box(self, closed: bool = True) -> bool:
        """Whether the circumcenter lies in the closed (or open) box, decided exactly."""
        if closed:
            return all(0 <= x <= 1 for x in self.center)
        return all(0 < x < 1 for x in self.center)


@dataclass(frozen=True)
class Measured:
    """An element measured exactly from its node list (see :func:`measure`).

    ``cycles``: its hull's faces as cycles of frame indices, counter-clockwise seen
    from outside (none: the nodes are flat); ``unit_volume``: its volume over the
    box's (0 when flat); ``sphere``: its circumsphere in the frame, ``None`` when the
    nodes are flat or not all on one sphere; ``center``: the sphere's centre in unit
    coordinates, ``None`` with it.
    """

    cycles: tuple[tuple[int, ...], ...]
    unit_volume: Fraction
    sphere: Sphere | None
    center: tuple[Fraction, Fraction, Fraction] | None


def measure(frame: Frame, members: Iterable[int],
            hull: tuple[tuple[tuple[int, ...], ...], Fraction] | None = None) -> Measured:
    """Measure the element whose vertices are ``members`` (indices into the frame), exactly: the one
    place a mesh, a pattern check and the dual get an element's faces, volume and sphere from.

    ``hull``: the ``(cycles, unit_volume)`` of an earlier measure of the same members at the same
    unit coordinates in a box of other lengths: the hull and the volume over the box's do not depend
    on the lengths (a positive scaling of the axes keeps faces, orientation and volume ratios), so
    they are taken as they are; the sphere is the lengths' own.
    """
    members = list(members)
    if hull is not None:
        cycles, volume = hull
    else:
        try:
            cycles = tuple(cycle for cycle, _ in hull_faces(frame, members))
        except ValueError:  # flat: no hull, no volume
            cycles = ()
        volume = Fraction(six_volume(frame.coords, cycles), 6 * frame.scale ** 3) if cycles else Fraction(0)
    sphere = frame.circumsphere(members)
    return Measured(cycles, volume, sphere, frame.center(sphere) if sphere is not None else None)


def polyhedron(frame: Frame, cell: Cell) -> Polyhedron:
    """Classify the faces of a cell and measure it exactly."""
    index = {node: i for i, node in enumerate(frame.ids)}
    cycles = [tuple(index[n] for n in face) for face in cell.faces]
    unit_volume = Fraction(six_volume(frame.coords, cycles), 6 * frame.scale**3)
    return Polyhedron(
        nodes=cell.nodes,
        faces=cell.faces,
        face_kinds=tuple(face_kind(frame, cycle) for cycle in cycles),
        unit_volume=unit_volume,
        center=cell.center,
    )
