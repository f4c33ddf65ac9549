"""Tessellate a 1-irregular base element (a cuboid or another shape): Delaunay cells, classified and measured."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Mapping, Sequence

from ..choices import DelaunayBackend
from .configuration import Configuration
from .delaunay import delaunay_cells
from .element_types import ElementType, classify
from .geometry import Frame, Rational
from .polyhedron import Polyhedron, polyhedron
from .box import Point

__all__ = ["Element", "Tessellation", "element_entry", "tessellate", "tessellation_elements"]


@dataclass(frozen=True)
class Element:
    """One element of a tessellation: its type and its nodes in the type's reference order.

    ``mirrored``: the element is the mirror image of its (chiral) type's direct
    form, so the catalogue's reference faces run the other way round on it.
    """

    type: ElementType
    nodes: tuple[int, ...]
    polyhedron: Polyhedron
    mirrored: bool = False

    @classmethod
    def from_polyhedron(cls, poly: Polyhedron) -> "Element":
        """The element a polyhedron is: its type by canonical code, its nodes in the type's reference order."""
        etype, order, mirrored = classify(poly)
        return cls(etype, order, poly, mirrored)


def element_entry(element: Element, scale: Sequence[float]) -> dict[str, object]:
    """An element as pattern-table data: type id, nodes in reference order, circumcenter in a
    box of edge lengths ``scale`` (floats), and ``mirror`` where it is its type's mirror image."""
    entry: dict[str, object] = {"type": element.type.id, "nodes": list(element.nodes),
             "circumcenter": [float(x) * s for x, s in zip(element.polyhedron.center, scale)]}
    if element.mirrored:
        entry["mirror"] = True
    return entry


@dataclass(frozen=True)
class Tessellation:
    """The Delaunay tessellation of one configuration (of a cuboid or another shape), elements sorted by node ids."""

    configuration: Configuration
    nodes: dict[int, Point]
    elements: tuple[Element, ...]

    @cached_property  # read per configuration by the studies' rows, counts and tables: exact comparisons, made once
    def fvm_adequate(self) -> bool:
        """Every element's circumcenter lies in the closed box, or the closed base element of another
        shape (the paper's FVM test)."""
        return all(self.configuration.contains(e.polyhedron.center) for e in self.elements)

    @property
    def fvm_adequate_open(self) -> bool:
        """Every element's circumcenter lies strictly inside the box (or the base element)."""
        return all(self.configuration.contains(e.polyhedron.center, closed=False) for e in self.elements)

    def circumcenter(self, element: Element) -> tuple[float, float, float]:
        """Float circumcenter of an element in the real box."""
        scale = self.configuration.box.to_float()
        center = element.polyhedron.center
        return (float(center[0]) * scale[0], float(center[1]) * scale[1], float(center[2]) * scale[2])


def tessellate(configuration: Configuration, backend: DelaunayBackend = "python") -> Tessellation:
    """The Delaunay tessellation of a configuration, its elements the largest co-spherical sets.

    Every cell is the convex hull of all points on one empty sphere, decided in
    integer arithmetic; each element is classified by the canonical code of its
    labelled face graph.

    Parameters
    ----------
    configuration : Configuration
        The base element in its box (the cuboid or another shape), its Steiner
        points, and its face and body points.
    backend : str
        The Delaunay walk (:func:`cospherical.core.delaunay.delaunay_cells`):
        ``"python"`` (the default, for small work) or ``"compiled"`` (bulk work
        that pays the compiled kernel's loading once); the same elements either way.

    Returns
    -------
    Tessellation
        The nodes (unit-box coordinates, exact), the elements sorted by node ids,
        and the FVM tests; :meth:`Tessellation.circumcenter` gives an element's
        circumcenter in box coordinates.

    Examples
    --------
    >>> from cospherical import Configuration
    >>> tess = tessellate(Configuration.from_code("800000000000"))
    >>> [e.type.name for e in tess.elements]
    ['Rectangular Pyramid', 'Rectangular Pyramid', 'Rectangular Pyramid', 'Rectangular Pyramid']
    >>> tess.fvm_adequate
    True

    Another base element (:mod:`cospherical.core.shapes`) goes through the same
    pipeline; its FVM test asks for circumcenters in that element:

    >>> from cospherical.core.shapes import standard_shape
    >>> tess = tessellate(Configuration.from_code("888888888", shape=standard_shape("prism")))
    >>> sorted(e.type.name for e in tess.elements), tess.fvm_adequate
    (['Cuboid', 'Cuboid', 'Triangular Prism', 'Triangular Prism', 'Triangular Prism', 'Triangular Prism'], True)
    >>> tess = tessellate(Configuration.from_code("800000", shape=standard_shape("tetrahedron")))
    >>> [e.type.name for e in tess.elements], sum(e.polyhedron.unit_volume for e in tess.elements)
    (['Tetrahedron', 'Tetrahedron'], Fraction(1, 6))
    """
    nodes = configuration.nodes()
    return Tessellation(configuration, nodes, tessellation_elements(nodes, configuration.box.squared, backend))


def tessellation_elements(nodes: Mapping[int, Sequence[Rational]], squared: Sequence[Rational],
                          backend: DelaunayBackend = "python") -> tuple[Element, ...]:
    """The classified Delaunay elements of points ``{node id: unit coordinates}`` in a box
    with these squared lengths: the one pipeline of every base element (cuboid or other shape).
    ``backend``: the Delaunay walk's, as in :func:`tessellate`."""
    frame = Frame.build(nodes, squared)
    elements = []
    for cell in delaunay_cells(frame, backend):
        elements.append(Element.from_polyhedron(polyhedron(frame, cell)))
    return tuple(elements)
