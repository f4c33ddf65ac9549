"""Exact checks of a whole mesh, one module each: volume, conformity, circumcenters in their leaf, global Delaunay.

Per-leaf properties (a configuration's volume, its circumcenters) are decided once per
distinct configuration, exactly, and counted over the leaves that have it.  Whole-mesh
properties are decided on the global vertex ids (conformity) and on the global vertex set
(Delaunay): a leaf's sphere can hold a vertex of a smaller neighbour, so no per-leaf test
can replace them.

- :mod:`~cospherical.mesh.checks.volume`: the volumes sum to the domain's (:func:`check_volume`);
- :mod:`~cospherical.mesh.checks.conformity`: faces met twice in opposite orientations, or once
  in the domain's boundary (:func:`check_conformity`, :func:`pair_faces` for any elements'
  faces, :func:`match_seams` across a partitioned mesh's pieces);
- :mod:`~cospherical.mesh.checks.circumcenters`: circumcenters in their own closed leaf and in
  the closed domain (:func:`check_circumcenters`);
- :mod:`~cospherical.mesh.checks.empty_sphere`: no vertex strictly inside any element's sphere,
  with the proof that the tree's structure bounds where the vertices near a sphere can be
  (:func:`check_delaunay`);
- :mod:`~cospherical.mesh.checks.domain`: where the domain's boundary and closed inside are,
  for a box or a device's union of boxes (:func:`on_domain_boundary`, :func:`in_closed_domain`).

Each check returns a frozen dataclass of what it found; the report's section of the checks
that ran is :class:`~cospherical.mesh.report_sections.ChecksSummary`.
"""

from __future__ import annotations

from .circumcenters import CircumcenterCheck, check_circumcenters
from .conformity import ConformityCheck, OpenFaces, check_conformity, element_faces, match_seams, pair_faces
from .domain import in_closed_domain, on_domain_boundary
from .empty_sphere import DelaunayCheck, check_delaunay, grid_weights
from .volume import VolumeCheck, check_volume

__all__ = ["CircumcenterCheck", "ConformityCheck", "DelaunayCheck", "OpenFaces", "VolumeCheck", "check_circumcenters",
           "check_conformity", "check_delaunay", "check_volume", "element_faces", "grid_weights", "match_seams",
           "in_closed_domain", "on_domain_boundary", "pair_faces"]
