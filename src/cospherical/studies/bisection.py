"""Studies: tessellate every configuration of a family, one per symmetry orbit.

A study tessellates only one member (the smallest code) of each orbit of the
box's symmetry group.  Statistics count every configuration through the orbit
sizes, since a symmetry maps element types and circumcenter tests to
themselves.  A member's own tessellation is the representative's mapped
through the symmetry and re-classified, so that its node orders are exactly
what a direct call gives.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from typing import Callable, Sequence

from ..catalogue import CRITERIA, Choice, choose
from ..core.configuration import Box, Configuration
from ..core.element_types import ElementType, classify
from ..core.symmetry import Symmetry, box_symmetries, orbit_representatives
from ..core.tessellation import Element, Tessellation, tessellate

__all__ = ["Study", "TypeCount", "bisection_codes", "map_tessellation", "run_study"]

Progress = Callable[[int], None]


def bisection_codes() -> list[str]:
    """The 4096 bisection configuration codes: a midpoint (``8``) or nothing on each edge."""
    return ["".join("8" if mask >> k & 1 else "0" for k in range(12)) for mask in range(4096)]


def map_tessellation(tess: Tessellation, sym: Symmetry, target: Configuration) -> Tessellation:
    """The image of ``tess`` under ``sym``; ``target`` is the image configuration."""
    elements = []
    for element in tess.elements:
        poly = sym.polyhedron(element.polyhedron)
        etype, order, mirrored = classify(poly)
        elements.append(Element(etype, order, poly, mirrored))
    elements.sort(key=lambda e: e.polyhedron.nodes)
    return Tessellation(target, target.nodes(), tuple(elements))


@dataclass(frozen=True)
class TypeCount:
    type: ElementType
    count: int
    configurations: int


@dataclass(frozen=True)
class Study:
    """Every configuration of one family on one box, tessellated once per orbit, per criterion."""

    name: str
    box: Box
    face_points: str
    codes: tuple[str, ...]
    representative: dict[str, tuple[str, Symmetry]]  # code -> (orbit representative, symmetry to it)
    choices: dict[str, Choice]  # criterion -> kept types and the representatives' tessellations

    @property
    def criteria(self) -> tuple[str, ...]:
        return tuple(self.choices)

    @property
    def tessellations(self) -> dict[str, Tessellation]:
        """Orbit representative -> its (optimal) tessellation."""
        return self.choices["optimal"].tessellations

    @property
    def configurations(self) -> int:
        return len(self.codes)

    @property
    def orbits(self) -> int:
        return len(self.tessellations)

    def orbit_sizes(self) -> Counter:
        return Counter(rep for rep, _ in self.representative.values())

    def tessellation(self, code: str, criterion: str = "optimal") -> Tessellation:
        """The tessellation of any configuration of the study under a criterion."""
        rep, _ = self.representative[code]
        return self.member_tessellation(code, self.choices[criterion].tessellations[rep])

    def member_tessellation(self, code: str, tess: Tessellation) -> Tessellation:
        """A tessellation of ``code``'s orbit representative, mapped onto ``code`` itself."""
        rep, sym = self.representative[code]
        if rep == code:
            return tess
        target = Configuration.from_code(code, self.box, self.face_points)
        return map_tessellation(tess, sym.inverse(), target)

    def _count(self, predicate: Callable[[Tessellation], bool]) -> int:
        return sum(size for rep, size in self.orbit_sizes().items() if predicate(self.tessellations[rep]))

    @property
    def fvm_adequate(self) -> int:
        return self._count(lambda t: t.fvm_adequate)

    @property
    def fvm_adequate_open(self) -> int:
        return self._count(lambda t: t.fvm_adequate_open)

    def total(self, criterion: str = "optimal") -> int:
        reps = self.choices[criterion].tessellations
        return sum(size * len(reps[rep].elements) for rep, size in self.orbit_sizes().items())

    def type_counts(self, criterion: str = "optimal") -> list[TypeCount]:
        """Element types by decreasing count, then id."""
        counts: Counter = Counter()
        configurations: Counter = Counter()
        types: dict[str, ElementType] = {}
        reps = self.choices[criterion].tessellations
        for rep, size in self.orbit_sizes().items():
            per_type = Counter(e.type.id for e in reps[rep].elements)
            for element in reps[rep].elements:
                types[element.type.id] = element.type
            for type_id, n in per_type.items():
                counts[type_id] += n * size
                configurations[type_id] += size
        return [
            TypeCount(types[i], counts[i], configurations[i])
            for i in sorted(counts, key=lambda i: (-counts[i], i))
        ]


def run_study(
    name: str,
    box: Box,
    codes: Sequence[str],
    face_points: str = "octree",
    progress: Progress | None = None,
    criteria: Sequence[str] = CRITERIA,
) -> Study:
    """Tessellate every configuration code, one per orbit of the box's symmetries.

    ``progress(n)`` is called as orbits are done, with the number of
    configurations they account for.  Each criterion (``optimal``,
    ``internal_faces``, ``internal_edges_and_faces``) gets its kept types and
    split tessellations.
    """
    symmetries = box_symmetries(box)
    reps, sym_index = orbit_representatives(codes, symmetries)
    representative = {code: (rep, symmetries[i]) for code, rep, i in zip(codes, reps, sym_index)}
    sizes = Counter(reps)
    tessellations = {}
    for rep in sorted(sizes):
        tessellations[rep] = tessellate(Configuration.from_code(rep, box, face_points))
        if progress:
            progress(sizes[rep])
    choices = {criterion: choose(tessellations, sizes, criterion) for criterion in criteria}
    return Study(name, box, face_points, tuple(codes), representative, choices)
