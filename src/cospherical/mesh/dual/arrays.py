"""The dual as arrays: :class:`Dual` (control volumes, edges and coefficients, boundary areas) and a device's
:class:`RegionParts`, floats beside their exact integer numerators, and the one conversion between them.

Exact arrays (``*_exact``) are int64, or Python integers in an object array when int64
could overflow (extreme boxes); :func:`as_floats` turns either into floats the same way
everywhere (the writer, and ``check`` when it recomputes them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction
from typing import TYPE_CHECKING, Any, Sequence

import numpy as np
from numpy.typing import NDArray

from ...core.configuration import Box
from ..report_sections import NegativeCoefficients

if TYPE_CHECKING:
    from scipy.sparse import csr_matrix

__all__ = ["Dual", "ExactArray", "InterfaceParts", "RegionParts", "as_floats", "boundary_areas"]

ExactArray = NDArray[Any]  # int64, or object (Python integers) where int64 could overflow


@dataclass
class Dual:
    """The dual of a mesh, as arrays (floats) with their exact integer forms.

    Vertices: ``grid_vertices`` (n x 3, integers of the grid of ``grid`` intervals per
    domain side) and ``vertices`` (their real coordinates); ``boundary`` (on the
    domain's boundary), ``control_volume``, ``boundary_area``.  Edges: ``edges``
    (m x 2, ``i < j``, sorted), ``length``, ``area`` (signed area of the dual face),
    ``coefficient`` (``area / length``).  Exact: ``coefficient == coefficient_exact *
    volume_factor / coefficient_denominator`` and ``control_volume == volume_exact *
    volume_factor / volume_denominator`` with integer numerators (int64, or Python
    integers in an object array when int64 could overflow) and ``volume_factor`` the
    box's ``a*b*c`` (``volume_factor_squared`` exact).  Boundary areas per axis ``k``
    (the part in the domain's two sides normal to ``k``): ``boundary_area ==
    sum over k of boundary_area_exact[:, k] * sqrt(boundary_factors_squared[k]) /
    boundary_area_denominator``, ``boundary_factors_squared`` the squared products of the
    two lengths of those sides, ``(b^2 c^2, a^2 c^2, a^2 b^2)``.  ``element_circumcenter``:
    the real circumcenter of every element, in the mesh's element order; ``element_nodes``
    and ``element_sizes``: the elements themselves (global vertex ids, padded with -1,
    as :meth:`~cospherical.mesh.assembly.Mesh.connectivity` gives them), from which the
    exact values can be computed again (``cospherical check`` does).

    A device's domain is a union of boxes, its boundary the faces met by one element
    (also inside the bounding box: a notch, a hole); there ``boundary``, the boundary
    areas and ``boundary_edge`` (per edge: it is an edge of such a face; not in the file,
    set where the faces are known: the mesher, ``cospherical check``) are the true
    boundary's (:func:`~cospherical.mesh.surfaces.set_domain_boundary`).  Without
    ``boundary_edge`` the boundary is the box's six sides.
    """

    box: Box
    grid: int
    grid_vertices: np.ndarray
    vertices: np.ndarray
    edges: np.ndarray
    length: np.ndarray
    area: np.ndarray
    coefficient: np.ndarray
    control_volume: np.ndarray
    boundary: np.ndarray
    boundary_area: np.ndarray
    coefficient_exact: np.ndarray
    coefficient_denominator: int
    volume_exact: np.ndarray
    volume_denominator: int
    volume_factor: float
    volume_factor_squared: Fraction
    boundary_area_exact: np.ndarray
    boundary_area_denominator: int
    boundary_factors_squared: tuple[Fraction, Fraction, Fraction]
    element_circumcenter: np.ndarray = field(repr=False)
    element_nodes: np.ndarray = field(repr=False)
    element_sizes: np.ndarray = field(repr=False)
    regions: "RegionParts | None" = field(default=None, repr=False)
    boundary_edge: NDArray[np.bool_] | None = field(default=None, repr=False)

    def laplacian(self) -> csr_matrix:
        """The box method's matrix: ``K[i, j] = -coefficient``, ``K[i, i]`` the row's sum (scipy.sparse CSR).

        Symmetric with zero row sums: ``K @ u`` is ``-div grad u`` integrated over the
        control volumes, so ``K u = M f`` with :meth:`mass` is the discrete Poisson
        problem.
        """
        from scipy.sparse import coo_matrix

        n = len(self.vertices)
        i, j = self.edges[:, 0], self.edges[:, 1]
        c = self.coefficient
        diagonal = np.bincount(i, weights=c, minlength=n) + np.bincount(j, weights=c, minlength=n)
        # one entry per position (no duplicates to sum), 32-bit indices while they fit: a third of the memory
        index = np.int32 if n < 2**31 else np.int64
        every = np.arange(n, dtype=index)
        rows = np.concatenate([i.astype(index), j.astype(index), every])
        cols = np.concatenate([j.astype(index), i.astype(index), every])
        return coo_matrix((np.concatenate([-c, -c, diagonal]), (rows, cols)), shape=(n, n)).tocsr()

    def mass(self) -> csr_matrix:
        """The lumped mass matrix: the control volumes on the diagonal (scipy.sparse)."""
        from scipy.sparse import diags

        return diags(self.control_volume).tocsr()

    def volume_sum(self) -> Fraction:
        """The control volumes' sum as an exact fraction of the domain's volume."""
        return Fraction(_exact_sum(self.volume_exact), self.volume_denominator)

    def boundary_area_sums(self) -> tuple[Fraction, Fraction, Fraction]:
        """Per axis, the boundary areas' sum as an exact fraction of one side's area (2: both sides normal to it)."""
        x, y, z = (Fraction(_exact_sum(self.boundary_area_exact[:, k]), self.boundary_area_denominator)
                   for k in range(3))
        return x, y, z

    def negative_coefficients(self) -> NegativeCoefficients:
        """Edges whose coefficient is negative (decided on the exact integers), interior and boundary apart.

        A boundary edge is an edge of a face in the domain's boundary: ``boundary_edge``
        when it is set, else an edge in one of the box's sides.
        """
        if self.boundary_edge is not None:
            below = self.coefficient_exact < 0
            return NegativeCoefficients(int((below & ~self.boundary_edge).sum()),
                                        int((below & self.boundary_edge).sum()))
        negative = np.flatnonzero(self.coefficient_exact < 0)  # few: only their ends are looked at
        g = self.grid_vertices
        a, b = g[self.edges[negative, 0]], g[self.edges[negative, 1]]
        on_plane = np.zeros(len(negative), dtype=bool)
        for side in (0, self.grid):
            on_plane |= np.any((a == side) & (b == side), axis=1)
        boundary = int(on_plane.sum())
        return NegativeCoefficients(len(negative) - boundary, boundary)


@dataclass
class RegionParts:
    """A device's dual split per region, and its contacts' areas per vertex, exactly.

    ``names``/``materials`` of the regions, ``element_region`` (per element, mesh order).
    Control-volume parts, one row per (vertex, region) pair, sorted:
    ``volume_vertex``, ``volume_region``, ``volume_exact`` over ``volume_denominator``
    (times the dual's ``volume_factor``, like its control volumes).  Coupling parts, one
    row per (edge, region): ``coupling_edge`` (index into the dual's edges),
    ``coupling_region``, ``coupling_exact`` over ``coupling_denominator`` (times
    ``volume_factor``, like the coefficients).  Contacts: ``contact_names``,
    ``contact_regions``, ``contact_boxes`` (exact texts, device units), the faces
    (``contact_face_nodes``, -1 padded, ``contact_face_contact``), and the area parts per
    (vertex, contact): ``contact_vertex``, ``contact_contact``, ``contact_exact`` over
    ``contact_denominator``, in device units (a device's lengths are rational).
    ``origin``: the device's bounding box's low corner (exact texts), where the grid starts;
    ``boxes``: per region its boxes (six exact texts each, device units): the domain.
    ``interfaces``: the faces between regions and their area per vertex
    (:class:`InterfaceParts`); ``None`` in a dual read from a version 4 file, whose
    boundary figures are the bounding box's sides.
    """

    names: tuple[str, ...]
    materials: tuple[str, ...]
    element_region: np.ndarray
    volume_vertex: np.ndarray
    volume_region: np.ndarray
    volume_exact: np.ndarray
    volume_denominator: int
    coupling_edge: np.ndarray
    coupling_region: np.ndarray
    coupling_exact: np.ndarray
    coupling_denominator: int
    contact_names: tuple[str, ...]
    contact_regions: tuple[int, ...]
    contact_boxes: tuple[tuple[str, ...], ...]
    contact_face_nodes: np.ndarray
    contact_face_contact: np.ndarray
    contact_vertex: np.ndarray
    contact_contact: np.ndarray
    contact_exact: np.ndarray
    contact_denominator: int
    volume_factor: float
    origin: tuple[str, ...] = ("0", "0", "0")
    boxes: tuple[tuple[tuple[str, ...], ...], ...] = ()
    interfaces: "InterfaceParts | None" = None

    @property
    def volume_part(self) -> np.ndarray:
        return as_floats(self.volume_exact, self.volume_denominator, self.volume_factor)

    @property
    def coupling_part(self) -> np.ndarray:
        return as_floats(self.coupling_exact, self.coupling_denominator, self.volume_factor)

    @property
    def contact_part(self) -> np.ndarray:
        return as_floats(self.contact_exact, self.contact_denominator, 1.0)

    def region_volumes(self) -> list[Fraction]:
        """Each region's control-volume parts summed, as exact multiples of ``volume_factor``."""
        return [Fraction(_exact_sum(self.volume_exact[self.volume_region == r]),
                         self.volume_denominator) for r in range(len(self.names))]

    def contact_areas(self) -> list[Fraction]:
        """Each contact's area parts summed, exactly (device units)."""
        return [Fraction(_exact_sum(self.contact_exact[self.contact_contact == c]),
                         self.contact_denominator) for c in range(len(self.contact_names))]


@dataclass
class InterfaceParts:
    """A device's interfaces, each a named set of faces, and each face's area split among its vertices, exactly.

    ``regions``: per interface its two touching regions ``(a, b)``, ``a < b`` (indices into
    :attr:`RegionParts.names`), named ``"a|b"`` (``names``); the faces: ``face_nodes``
    (polygons of vertex ids, -1 padded, counter-clockwise seen from region ``a``'s side:
    their normal points into ``b``), ``face_interface``; the area parts, one row per
    (vertex, interface), sorted: ``vertex``, ``interface``, ``exact`` over ``denominator``
    in device units (``part`` as floats): the box method's boundary pieces, as a contact's
    (the triangles between the vertex, its edges' midpoints and the face's circle centre).
    A vertex's part is the interface's area in its control volume, seen from either region.
    """

    regions: NDArray[np.int32]
    names: tuple[str, ...]
    face_nodes: NDArray[np.int32]
    face_interface: NDArray[np.int32]
    vertex: NDArray[np.int64]
    interface: NDArray[np.int32]
    exact: ExactArray
    denominator: int

    @property
    def part(self) -> NDArray[np.float64]:
        return as_floats(self.exact, self.denominator, 1.0)

    def areas(self) -> list[Fraction]:
        """Each interface's area parts summed, exactly (device units)."""
        return [Fraction(_exact_sum(self.exact[self.interface == i]), self.denominator)
                for i in range(len(self.regions))]


def _exact_sum(values: ExactArray) -> int:
    """The sum of exact integers: in int64 where no partial sum can leave it (their count times the largest
    magnitude below 2**63), as Python integers otherwise (object arrays, or int64 that could overflow)."""
    if values.dtype != object and len(values):
        largest = max(int(values.max()), -int(values.min()))
        if largest * len(values) < 2**63:
            return int(values.sum(dtype=np.int64))
    return int(np.sum(values.astype(object)))


def boundary_areas(exact: ExactArray, denominator: int, factors_squared: Sequence[Fraction]) -> NDArray[np.float64]:
    """The boundary areas as floats from their exact per-axis numerators (see :class:`Dual`)."""
    factors = np.array([math.sqrt(f) for f in factors_squared])
    if exact.dtype == object:  # numbers past float's range (extreme boxes): divided as Python integers first
        areas: NDArray[np.float64] = (as_floats(exact.reshape(-1), denominator, 1.0).reshape(exact.shape) * factors
                                      ).sum(axis=1)
        return areas
    # (x0 f0 + x1 f1) + x2 f2, the order and so the bits of numpy's sum over each row of three products, one
    # column at a time (no array of every product)
    areas = exact[:, 0] * factors[0]
    for k in (1, 2):
        areas += exact[:, k] * factors[k]
    areas /= denominator
    return areas


def as_floats(exact: ExactArray, den: int, factor: float) -> NDArray[np.float64]:
    """``exact / den * factor`` as floats.  Python integers (extreme boxes: 1e-12 x 1 x 3e9 gives numerators
    and denominators past float's range) are divided exactly first, Python's int / int rounding once."""
    if exact.dtype != object:
        floats: NDArray[np.float64] = exact.astype(np.float64)
        floats *= factor / float(den)  # in place: one array of the result's size, not two
    else:
        floats = np.array([x / den for x in exact.tolist()], dtype=np.float64) * factor
    return floats


