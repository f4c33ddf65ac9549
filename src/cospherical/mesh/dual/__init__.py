"""The finite-volume dual of a mesh: control volumes and coupling coefficients, exactly.

The box method (vertex-centred finite volumes) gives every vertex the part of the
domain nearer to it than to any other vertex (its Voronoi cell, clipped to the
domain) and couples two vertices joined by a mesh edge with the area of their
common Voronoi face over the edge's length.  In a mesh of co-spherical elements
both are sums of element-wise pieces, computed exactly, and the mesh's sums are
integer sums, assembled by array indexing; floats appear only in the ``float``
outputs.  The steps, one module each, bottom to top:

- :mod:`~cospherical.mesh.dual.pieces`: one element's exact pieces
  (:func:`element_pieces`), rationals in the box's frame;
- :mod:`~cospherical.mesh.dual.arrays`: the result, :class:`Dual` (and a device's
  :class:`RegionParts`), floats beside their exact integer numerators;
- :mod:`~cospherical.mesh.dual.shapes`: the pieces once per configuration (they
  scale with the leaf's size), per cell shape, or per distinct element shape, with
  the members that share them;
- :mod:`~cospherical.mesh.dual.sums`: :func:`mesh_dual`, the groups scattered into
  the edge and vertex arrays;
- :mod:`~cospherical.mesh.dual.tetrahedral`: the outside oracle (TetGen or Qhull) for
  the report's tetrahedral comparison, and :mod:`~cospherical.mesh.dual.summary`,
  the report's figures (:func:`dual_summary`).

Examples
--------
>>> from cospherical.core.configuration import Box
>>> from cospherical.mesh.octree import build_octree, parse_shape
>>> from cospherical.mesh.assembly import assemble
>>> dual = mesh_dual(assemble(build_octree(Box.parse([1, 1, 1]), 1, [parse_shape("point:0.5,0.5,0.5")])))
>>> len(dual.edges), dual.volume_sum(), float(dual.control_volume.max())
(54, Fraction(1, 1), 0.125)
"""

from __future__ import annotations

from .arrays import Dual, InterfaceParts, RegionParts, as_floats, boundary_areas
from .pieces import ElementPieces, element_pieces
from .summary import DualFigures, dual_summary
from .sums import mesh_dual
from .tetrahedral import TETRAHEDRAL_LIMIT, external_tetrahedra, tetrahedral_counts

__all__ = ["Dual", "DualFigures", "ElementPieces", "InterfaceParts", "RegionParts", "TETRAHEDRAL_LIMIT", "as_floats", "boundary_areas", "dual_summary",
           "element_pieces", "external_tetrahedra", "mesh_dual", "tetrahedral_counts"]
