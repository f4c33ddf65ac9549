"""The circumcenter checks: each element's circumcenter in its own closed leaf (the box method's FVM
test), decided once per configuration and counted over its leaves; and in the closed domain."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..assembly import Mesh
from .domain import in_closed_domain

__all__ = ["CircumcenterCheck", "check_circumcenters"]


@dataclass(frozen=True)
class CircumcenterCheck:
    """What :func:`check_circumcenters` found: where the elements' circumcenters lie, decided exactly.

    Attributes
    ----------
    circumcenters_outside_leaf : int
        Elements whose circumcenter lies outside their own closed leaf (a cell of the global
        Delaunay subdivision counts against its first leaf).
    leaves_not_fvm_adequate : int
        Leaves with at least one such leaf element.
    elements_not_cospherical : int
        Elements whose nodes are not on one sphere: not Delaunay elements at all.
    boundary_circumcenters_outside : int
        Elements whose circumcenter lies outside the closed domain.
    """

    circumcenters_outside_leaf: int
    leaves_not_fvm_adequate: int
    elements_not_cospherical: int
    boundary_circumcenters_outside: int

    def figures(self) -> dict[str, int]:
        """The counts as the report names them, in its order."""
        return {"circumcenters_outside_leaf": self.circumcenters_outside_leaf,
                "leaves_not_fvm_adequate": self.leaves_not_fvm_adequate,
                "elements_not_cospherical": self.elements_not_cospherical,
                "boundary_circumcenters_outside": self.boundary_circumcenters_outside}


def check_circumcenters(mesh: Mesh) -> CircumcenterCheck:
    """Circumcenters in their own closed leaf, decided exactly per configuration, counted over the leaves.

    Returns a :class:`CircumcenterCheck`: elements whose circumcenter lies outside their
    leaf, leaves not FVM-adequate, elements not co-spherical, and elements whose
    circumcenter lies outside the closed domain.  Only elements at the boundary can have one (an empty sphere
    whose centre is beyond a boundary plane cuts it); there the box method's
    control volumes need the circumcenter inside, as the paper says.
    """
    outside = leaves_bad = not_spherical = 0
    for _, tessellation, leaves in mesh.groups():
        outside += sum(not e.center_in_leaf for e in tessellation.elements) * len(leaves)
        not_spherical += sum(e.sphere is None for e in tessellation.elements) * len(leaves)
        if not tessellation.fvm_adequate:
            leaves_bad += len(leaves)
    if mesh.cells is not None:
        outside += int((~mesh.cell_center_in_leaf()).sum())
    return CircumcenterCheck(int(outside), int(leaves_bad), int(not_spherical), _outside_domain(mesh))


def _outside_domain(mesh: Mesh) -> int:
    """Elements whose circumcenter lies outside the closed domain (a device's: its union of boxes), decided
    exactly in grid units."""
    grid = mesh.grid
    layout = mesh.regions.layout if mesh.regions is not None else None
    size = mesh.leaf_size()
    outside = 0
    for _, tessellation, leaves in mesh.groups():
        low = mesh.tree.positions[leaves].astype(np.int64) * size[leaves, None]
        for element in tessellation.elements:
            if element.center is None or element.center_in_leaf:
                continue  # a centre in its own closed leaf is in the closed domain: the leaf is
            # the centre in grid units is low + c * size, for c = p / q: compare q * low + p * size with 0 and q * grid,
            # in int64 when every term is below 2**62 (low and size are at most grid), else in Python integers
            numerators = [c.numerator for c in element.center]
            denominators = [c.denominator for c in element.center]
            kind = np.int64 if grid * (max(denominators) + max(map(abs, numerators))) < 2**62 else object
            p, q = np.array(numerators, dtype=kind), np.array(denominators, dtype=kind)
            at = low.astype(kind) * q[None] + p[None] * size[leaves, None].astype(kind)
            outside += int((~in_closed_domain(at, q[None], grid, layout)).sum())
    if mesh.cells is not None:
        num, den = mesh.cell_centers()
        outside += int((~in_closed_domain(num, den[:, None], grid, layout)).sum())
    return outside
