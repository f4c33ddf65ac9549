"""The base element of a study: the cuboid or another standard shape in a box.

What a study, a table check or a mesher needs of its base element, in one typed
object: configurations from codes, the symmetry group, the orbit
representatives of codes under it (the cube's fast paths stay behind
:func:`~cospherical.core.symmetry.orbit_representatives`), and the
tessellation.  The cuboid is one of the standard shapes here.

Examples
--------
>>> prism = base_element("prism", Box.parse(["1", "1", "1"]))
>>> len(prism.symmetries), prism.configuration("888888888").point_faces
(4, frozenset({2, 3, 4}))
>>> len(base_element("cuboid", Box.parse(["1", "2", "4"])).symmetries)
8
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Sequence

from ..caches import cached
from ..choices import DelaunayBackend, FacePointSource, OrbitBackend
from .configuration import Box, Configuration
from .shapes import ELEMENTS, Shape, standard_shape
from .symmetry import Symmetry, orbit_representatives, shape_symmetries
from .tessellation import Tessellation, tessellate

__all__ = ["ELEMENTS", "BaseElement", "base_element"]

@dataclass(frozen=True)
class BaseElement:
    """A base element (``cuboid``, ``prism``, ``pyramid``, ``tetrahedron``) in a box, under a face-point policy.

    ``shape`` is its :class:`~cospherical.core.shapes.Shape` (the cuboid's numbering is the
    VTK hexahedron's).
    """

    name: str
    box: Box
    face_points: FacePointSource = "octree"

    @cached_property
    def shape(self) -> Shape:
        return standard_shape(self.name, self.box)

    @property
    def edges(self) -> int:
        """The number of edges, hence of digits in a configuration code."""
        return len(self.shape.edges)

    def configuration(self, code: str) -> Configuration:
        """The configuration of a code, optionally with a point suffix ``+f...``."""
        return Configuration.from_code(code, face_points=self.face_points, shape=self.shape)

    @cached_property
    def symmetries(self) -> tuple[Symmetry, ...]:
        """The isometries of the element in its box, identity first."""
        return shape_symmetries(self.shape)

    def orbit_representatives(self, codes: Sequence[str], backend: OrbitBackend = "python") -> tuple[list[str], list[int]]:
        """For each code, its orbit's representative (the smallest image) and the index in
        :attr:`symmetries` of a symmetry taking the code to it (``backend``: the cube's fast
        path, as in :func:`~cospherical.core.symmetry.orbit_representatives`)."""
        return orbit_representatives(codes, self.symmetries, backend)

    def tessellate(self, configuration: Configuration, backend: DelaunayBackend = "python") -> Tessellation:
        """The Delaunay tessellation of one of this element's configurations (``backend``: the
        Delaunay walk's, as in :func:`~cospherical.core.tessellation.tessellate`)."""
        return tessellate(configuration, backend)

@cached(maxsize=64)  # a study maps every member's configuration through it
def base_element(name: str, box: Box, face_points: FacePointSource = "octree") -> BaseElement:
    """The :class:`BaseElement` named ``name`` in ``box`` (one object per element, box and policy)."""
    element = BaseElement(name, box, face_points)
    element.shape  # a name that is no standard shape is refused here, not at first use
    return element
