"""Studies: tessellate every configuration of a family, one per symmetry orbit.

A study tessellates only one member (the smallest code) of each orbit of the
base element's symmetry group (the box's for a cuboid; for a prism, pyramid or
tetrahedron the isometries of that shape, :mod:`cospherical.core.base_element`).  Statistics count every configuration through the orbit
sizes, since a symmetry maps element types and circumcenter tests to
themselves.  A member's own tessellation is the representative's mapped
through the symmetry and re-classified, so that its node orders are exactly
what a direct call gives.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, replace
from functools import partial
from typing import Callable, Iterator, Sequence

from ..catalogue import Choice, choose
from ..choices import CRITERIA, FacePointSource
from ..core.base_element import base_element
from ..core.configuration import Box, Configuration
from ..core.element_types import ElementType
from ..core.shapes import mask_codes, standard_shape
from ..core.symmetry import Symmetry
from ..core.tessellation import Element, Tessellation

__all__ = ["Progress", "Study", "TypeCount", "bisection_codes", "map_tessellation", "run_study"]

Progress = Callable[[int], None]


def bisection_codes(element: str = "cuboid") -> list[str]:
    """The bisection configuration codes of a base element: a midpoint (``8``) or nothing on each
    edge (4096 for the cuboid; 512, 256 and 64 for the prism, pyramid and tetrahedron).

    >>> len(bisection_codes()), bisection_codes("tetrahedron")[:3]
    (4096, ['000000', '800000', '080000'])
    """
    return mask_codes(len(standard_shape(element).edges))


def map_tessellation(tess: Tessellation, sym: Symmetry, target: Configuration,
                     images: ElementImages | None = None) -> Tessellation:
    """The image of ``tess`` under ``sym``; ``target`` is the image configuration.

    ``images``: the elements already mapped while mapping other tessellations of the
    same base element and point set (see :class:`ElementImages`), reused, and added to.
    """
    if images is None:
        elements = [Element.from_polyhedron(sym.polyhedron(element.polyhedron)) for element in tess.elements]
    else:
        elements = [images.image(element, sym) for element in tess.elements]
    elements.sort(key=lambda e: e.polyhedron.nodes)
    return replace(tess, configuration=target, nodes=target.nodes(), elements=tuple(elements))


class ElementImages:
    """Elements mapped by symmetries, each equal (polyhedron, symmetry) pair once.

    Mapping a study onto every configuration maps the same elements again and
    again: the paper's nine pattern tables map 326,523 elements, of which 69,874
    are new (a corner's tetrahedron is in thousands of configurations).  An image depends on the polyhedron only (its nodes, faces,
    face kinds, volume and centre), so equal polyhedra share it; the same image
    object is returned each time, which lets a writer remember its text too.

    Every element and image asked for is kept (the ids below stay theirs) for as
    long as this object lives: one table's pass over a study.
    """

    def __init__(self) -> None:
        self._known: dict[int, tuple[Element, int]] = {}  # id(element) -> (element, index of its polyhedron)
        self._polyhedra: dict[object, int] = {}  # polyhedron -> index, by value (hashed once per element)
        self._images: dict[tuple[int, tuple[int, ...]], Element] = {}  # (index, corner map) -> image

    def image(self, element: Element, sym: Symmetry) -> Element:
        """``element``'s image under ``sym``, re-classified as a direct tessellation classifies it."""
        known = self._known.get(id(element))
        if known is None:
            known = self._known[id(element)] = (element, self._polyhedra.setdefault(element.polyhedron,
                                                                                   len(self._polyhedra)))
        key = (known[1], sym.corner_map)
        image = self._images.get(key)
        if image is None:
            image = self._images[key] = Element.from_polyhedron(sym.polyhedron(element.polyhedron))
        return image


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
    face_points: FacePointSource
    codes: tuple[str, ...]
    representative: dict[str, tuple[str, Symmetry]]  # code -> (orbit representative, symmetry to it)
    choices: dict[str, Choice]  # criterion -> kept types and the representatives' tessellations
    element: str = "cuboid"  # the base element: cuboid, prism, pyramid or tetrahedron

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

    def orbit_sizes(self) -> Counter[str]:
        return Counter(rep for rep, _ in self.representative.values())

    def tessellation(self, code: str, criterion: str = "optimal") -> Tessellation:
        """The tessellation of any configuration of the study under a criterion."""
        rep, _ = self.representative[code]
        return self.member_tessellation(code, self.choices[criterion].tessellations[rep])

    def member_tessellation(self, code: str, tess: Tessellation, images: ElementImages | None = None) -> Tessellation:
        """A tessellation of ``code``'s orbit representative, mapped onto ``code`` itself
        (``images``: as :func:`map_tessellation`'s)."""
        rep, sym = self.representative[code]
        if rep == code:
            return tess
        target = base_element(self.element, self.box, self.face_points).configuration(code)
        return map_tessellation(tess, sym.inverse(), target, images)

    def rows(self) -> Iterator[tuple[str, bool, dict[str, Tessellation], Callable[[Tessellation], Tessellation]]]:
        """What a pattern table holds of each configuration, in code order: its code, whether it
        is FVM-adequate, its orbit representative's tessellation per criterion, and the map of
        those onto the configuration itself (the same element objects for equal images)."""
        images = ElementImages()
        for code in sorted(self.codes):
            rep, _ = self.representative[code]
            yield (code,
                   self.tessellations[rep].fvm_adequate,  # a symmetry keeps circumcenters in the box
                   {criterion: self.choices[criterion].tessellations[rep] for criterion in self.criteria},
                   partial(self.member_tessellation, code, images=images))

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
        counts: Counter[str] = Counter()
        configurations: Counter[str] = Counter()
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
    face_points: FacePointSource = "octree",
    progress: Progress | None = None,
    criteria: Sequence[str] = CRITERIA,
    element: str = "cuboid",
    known: Sequence[Study] = (),
) -> Study:
    """Tessellate every configuration code of a base element, one per orbit of its symmetries.

    ``progress(n)`` is called as orbits are done, with the number of
    configurations they account for.  Each criterion (``optimal``,
    ``internal_faces``, ``internal_edges_and_faces``) gets its kept types and
    split tessellations.  ``known``: other studies, whose representatives'
    tessellations are taken (for this study's configuration) wherever one has
    exactly the same points in the same shape: the Delaunay tessellation is
    the points' (two thirds of a bisection study under the ``none`` policy are
    its ``octree`` study's configurations without a face point, and most leaf
    configurations are one of the two).

    Examples
    --------
    >>> study = run_study("bisection", Box.parse(["1", "1", "1"]), bisection_codes("tetrahedron"),
    ...                   element="tetrahedron")
    >>> study.configurations, study.orbits, study.total(), study.fvm_adequate
    (64, 20, 206, 7)
    """
    family = base_element(element, box, face_points)
    symmetries = family.symmetries
    reps, sym_index = family.orbit_representatives(codes)
    representative = {code: (rep, symmetries[i]) for code, rep, i in zip(codes, reps, sym_index)}
    sizes = Counter(reps)
    by_points = {tess.configuration.point_set_code: tess for study in known for tess in study.tessellations.values()}
    by_points.pop(None, None)  # no code names those point sets
    tessellations = {}
    for rep in sorted(sizes):
        configuration = family.configuration(rep)
        same = by_points.get(configuration.point_set_code)
        if same is not None and same.configuration.shape == configuration.shape:
            tessellations[rep] = replace(same, configuration=configuration)
        else:
            tessellations[rep] = family.tessellate(configuration)
        if progress:
            progress(sizes[rep])
    choices = {criterion: choose(tessellations, sizes, criterion) for criterion in criteria}
    return Study(name, box, face_points, tuple(codes), representative, choices, element)
