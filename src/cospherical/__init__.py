"""cospherical: Delaunay tessellations of 1-irregular cuboids with co-spherical elements.

The public API, re-exported here from the modules that define it.  The names load on
first use, so ``import cospherical`` stays cheap for the command line.

- Configurations and tessellations: ``Box``, ``Configuration``, ``Length`` (an exact
  length), ``tessellate``, ``Tessellation``, ``Element``, ``ElementType``; the base elements
  (the cuboid, a prism, pyramid, tetrahedron or any convex shape): ``Shape``, ``standard_shape``.
- The element catalogue: ``Catalogue`` (its types by id or code, kept sets), ``shipped_catalogue``,
  ``load_catalogue``, ``type_name``.
- Pattern tables: ``load_patterns``, ``PatternTable``.
- A mesh of an octree in one call: ``build_mesh`` (refine shapes, a leaf list, a tree or a device in,
  an ``OctreeMesh`` out: vertices, elements, the exact report ``MeshReport``, the dual, its
  files, ``to_pyvista``, ``to_meshio``) and ``from_treemesh`` (a ``discretize.TreeMesh`` in).
- Errors: ``CosphericalError`` and its kinds ``InputError``, ``FormatError``, ``UsageError``;
  and ``__version__``.

The mesher's steps are in its package, :mod:`cospherical.mesh` (``pipeline.run_pipeline``, ``octree.build_octree``,
``octree.leaves_octree``, ``assembly.assemble``, ``report.mesh_report``), its files in
:mod:`cospherical.formats.mesh`; the command line is ``cospherical.cli.main``.  Each module's
``__all__`` says what it makes public; a name with a leading underscore is internal.

The layers, top to bottom, each importing only from those below it: ``cli``, ``api``, ``outputs``,
``adapters``, ``formats``, ``mesh``, ``studies``, ``catalogue``, ``paper``, ``core``, ``files`` and
``execution``, then ``errors``, ``version``, ``caches`` and ``choices`` (pyproject.toml's import-linter
contracts).

Examples
--------
>>> from cospherical import Configuration, tessellate
>>> tess = tessellate(Configuration.from_code("888888888888"))
>>> len(tess.elements), tess.elements[0].type.name
(8, 'Cuboid')
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .errors import CosphericalError, FormatError, InputError, UsageError
from .lazy import on_first_use
from .version import __version__

# name -> module that defines it
_API: dict[str, str | tuple[str, str]] = {
    "Box": "cospherical.core.configuration",
    "Configuration": "cospherical.core.configuration",
    "Length": "cospherical.core.exact",
    "ElementType": "cospherical.core.element_types",
    "Element": "cospherical.core.tessellation",
    "Shape": "cospherical.core.shapes",
    "standard_shape": "cospherical.core.shapes",
    "Tessellation": "cospherical.core.tessellation",
    "tessellate": "cospherical.core.tessellation",
    "Catalogue": "cospherical.catalogue",
    "load_catalogue": "cospherical.catalogue",
    "shipped_catalogue": "cospherical.catalogue",
    "type_name": "cospherical.catalogue",
    "PatternTable": "cospherical.formats.patterns",
    "load_patterns": ("cospherical.formats.patterns", "load"),
    "build_mesh": "cospherical.api.mesh",
    "OctreeMesh": "cospherical.api.mesh",
    "from_treemesh": "cospherical.api.mesh",
    "MeshReport": "cospherical.mesh.report",
    "ChecksSummary": "cospherical.mesh.report",
    "ConfigurationFrequency": "cospherical.mesh.report",
    "ContactSummary": "cospherical.mesh.report",
    "DelaunaySpheres": "cospherical.mesh.report",
    "DeviceSummary": "cospherical.mesh.report",
    "DualSummary": "cospherical.mesh.report",
    "InterfaceSummary": "cospherical.mesh.report",
    "LeafMeshSummary": "cospherical.mesh.report",
    "MixedCounts": "cospherical.mesh.report",
    "NegativeCoefficients": "cospherical.mesh.report",
    "OutsideType": "cospherical.mesh.report",
    "RegionSummary": "cospherical.mesh.report",
    "TetrahedralCounts": "cospherical.mesh.report",
    "TreeSummary": "cospherical.mesh.report",
    "TypeFrequency": "cospherical.mesh.report",
    "UniformSummary": "cospherical.mesh.report",
}

if TYPE_CHECKING:  # a type checker sees the names _API loads on first use (X as X: re-exported)
    from .core.configuration import Box as Box, Configuration as Configuration
    from .core.exact import Length as Length
    from .core.element_types import ElementType as ElementType
    from .core.tessellation import Element as Element, Tessellation as Tessellation, tessellate as tessellate
    from .core.shapes import Shape as Shape, standard_shape as standard_shape
    from .catalogue import Catalogue as Catalogue, load_catalogue as load_catalogue
    from .catalogue import shipped_catalogue as shipped_catalogue
    from .catalogue import type_name as type_name
    from .formats.patterns import PatternTable as PatternTable
    from .formats import patterns as _patterns
    load_patterns = _patterns.load  # a name of its own here: an assignment, which a checker sees exported
    from .api.mesh import build_mesh as build_mesh, OctreeMesh as OctreeMesh, from_treemesh as from_treemesh
    from .mesh.report import MeshReport as MeshReport
    from .mesh.report import ChecksSummary as ChecksSummary, ConfigurationFrequency as ConfigurationFrequency, ContactSummary as ContactSummary
    from .mesh.report import DelaunaySpheres as DelaunaySpheres, DeviceSummary as DeviceSummary, DualSummary as DualSummary
    from .mesh.report import InterfaceSummary as InterfaceSummary, LeafMeshSummary as LeafMeshSummary, MixedCounts as MixedCounts
    from .mesh.report import NegativeCoefficients as NegativeCoefficients, OutsideType as OutsideType, RegionSummary as RegionSummary
    from .mesh.report import TetrahedralCounts as TetrahedralCounts, TreeSummary as TreeSummary, TypeFrequency as TypeFrequency
    from .mesh.report import UniformSummary as UniformSummary

__all__ = ["CosphericalError", "FormatError", "InputError", "UsageError", "__version__", *_API]


__getattr__ = on_first_use(globals(), _API)


def __dir__() -> list[str]:
    return sorted(__all__)
