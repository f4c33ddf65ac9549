"""The report's sections that only ``--dual`` and a device write: the dual's figures and the device's regions.

Their public names are :mod:`cospherical.mesh.report_sections`' (import them from there);
they live here so that a mesh without a dual or a device does not make their eight
frozen dataclasses when it starts (~0.5 ms each): ``report_sections`` loads this module
the first time one of them is asked for.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar, Mapping

from .report_sections import _only_fields, _Section, _strings

__all__ = ["ContactSummary", "DeviceSummary", "DualSummary", "InterfaceSummary", "MixedCounts", "NegativeCoefficients",
           "RegionSummary", "TetrahedralCounts"]


@dataclass(frozen=True)
class NegativeCoefficients(_Section):
    """Edges whose box-method coefficient is negative, decided exactly (``negative_coefficients``).

    Attributes
    ----------
    interior : int
        Off the domain's boundary (nonzero: the mesh is not Delaunay there).
    boundary : int
        In a boundary plane of the domain.
    """

    interior: int
    boundary: int

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> NegativeCoefficients:
        """The section of a ``report.json`` ``negative_coefficients`` object."""
        return cls(**data)


@dataclass(frozen=True)
class MixedCounts(_Section):
    """The mixed mesh's sizes beside a tetrahedral one's (``dual.mixed``).

    Attributes
    ----------
    elements, edges, faces : int
        The mesh's elements, edges and faces (interior and boundary).
    nonzeros : int
        The box-method matrix's nonzeros (vertices plus twice the edges).
    """

    elements: int
    edges: int
    faces: int
    nonzeros: int

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> MixedCounts:
        """The section of a ``report.json`` ``dual.mixed`` object."""
        return cls(**data)


@dataclass(frozen=True)
class TetrahedralCounts(_Section):
    """A tetrahedral Delaunay mesh of the same vertices by an outside mesher, its sizes (``dual.tetrahedral``).

    Attributes
    ----------
    tool : str
        ``tetgen``, else ``qhull``.
    elements, edges, faces : int
        Its tetrahedra, edges and faces.
    nonzeros : int
        Its box-method matrix's nonzeros (vertices plus twice the edges).
    flat : int
        Qhull's flat tetrahedra left out (0 with TetGen).
    """

    tool: str
    elements: int
    edges: int
    faces: int
    nonzeros: int
    flat: int

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> TetrahedralCounts:
        """The section of a ``report.json`` ``dual.tetrahedral`` object."""
        return cls(**data)


@dataclass(frozen=True)
class DualSummary(_Section):
    """The figures of the exact finite-volume dual (``dual``).

    Attributes
    ----------
    edges : int
        The dual's edges (the mesh's).
    volume_sum : str
        The control volumes' sum as an exact fraction of the domain.
    coefficient_min, coefficient_max : float or None
        The least and greatest box-method coefficients (``None``: no edge).
    boundary_vertices : int
        Vertices on the domain's boundary.
    mixed : MixedCounts
        The mixed mesh's sizes.
    tetrahedral : TetrahedralCounts or None
        A tetrahedral Delaunay mesh's, when asked for (and up to a million vertices).
    """

    edges: int
    volume_sum: str
    coefficient_min: float | None
    coefficient_max: float | None
    boundary_vertices: int
    mixed: MixedCounts
    tetrahedral: TetrahedralCounts | None

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> DualSummary:
        """The section of a ``report.json`` ``dual`` object."""
        tetrahedral = _only_fields(cls, data)["tetrahedral"]
        return cls(data["edges"], data["volume_sum"], data["coefficient_min"], data["coefficient_max"],
                   data["boundary_vertices"], MixedCounts.from_dict(data["mixed"]),
                   TetrahedralCounts.from_dict(tetrahedral) if tetrahedral is not None else None)


@dataclass(frozen=True)
class RegionSummary(_Section):
    """A device region's figures (``device.regions``).

    Attributes
    ----------
    name, material : str
        The region's name and material.
    elements, nodes : int
        Its elements and the vertices they use.
    volume : str
        Its elements' volume, exact (the device's units).
    volume_ok : bool
        Whether it is exactly the region's boxes' volume.
    negative_coefficients : NegativeCoefficients or None
        With the dual: its edges' negative coefficients (``None``, absent, without).
    control_volume_sum : str or None
        With the dual: its control volumes' sum, exact (``None``, absent, without).
    """

    _ABSENT_WHEN_NONE: ClassVar[frozenset[str]] = frozenset({"negative_coefficients", "control_volume_sum"})

    name: str
    material: str
    elements: int
    nodes: int
    volume: str
    volume_ok: bool
    negative_coefficients: NegativeCoefficients | None = None
    control_volume_sum: str | None = None

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> RegionSummary:
        """The entry of a ``report.json`` ``device.regions`` list."""
        negative = data.get("negative_coefficients")
        return cls(**{**data, "negative_coefficients":
                      NegativeCoefficients.from_dict(negative) if negative is not None else None})


@dataclass(frozen=True)
class ContactSummary(_Section):
    """A device contact's figures (``device.contacts``).

    Attributes
    ----------
    name, region : str
        The contact's name and the region it touches.
    faces, nodes : int
        Its mesh faces and their vertices.
    area : str
        Its faces' area, exact.
    area_ok : bool
        Whether it is exactly the contact's rectangle's area.
    area_parts_sum : str or None
        With the dual: its dual's boundary area parts summed, exact (``None``, absent, without).
    """

    _ABSENT_WHEN_NONE: ClassVar[frozenset[str]] = frozenset({"area_parts_sum"})

    name: str
    region: str
    faces: int
    nodes: int
    area: str
    area_ok: bool
    area_parts_sum: str | None = None

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ContactSummary:
        """The entry of a ``report.json`` ``device.contacts`` list."""
        return cls(**data)


@dataclass(frozen=True)
class InterfaceSummary(_Section):
    """An interface between two device regions (``device.interfaces``).

    Attributes
    ----------
    name : str
        The interface's name.
    faces, nodes : int
        Its mesh faces and their vertices.
    """

    name: str
    faces: int
    nodes: int

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> InterfaceSummary:
        """The entry of a ``report.json`` ``device.interfaces`` list."""
        return cls(**data)


@dataclass(frozen=True)
class DeviceSummary(_Section):
    """A device's regions, contacts and interfaces (``device``).

    Attributes
    ----------
    name : str
        The device's name.
    resolving_level : int
        The level at which every box boundary lies on leaf faces.
    depth : int
        The tree's deepest level.
    origin : tuple of str
        The device's lowest corner, exact (text).
    regions : tuple of RegionSummary
    contacts : tuple of ContactSummary
    interfaces : tuple of InterfaceSummary
    """

    name: str
    resolving_level: int
    depth: int
    origin: tuple[str, str, str]
    regions: tuple[RegionSummary, ...]
    contacts: tuple[ContactSummary, ...]
    interfaces: tuple[InterfaceSummary, ...]

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> DeviceSummary:
        """The section of a ``report.json`` ``device`` object."""
        x, y, z = _strings(_only_fields(cls, data)["origin"])
        return cls(data["name"], data["resolving_level"], data["depth"], (x, y, z),
                   tuple(RegionSummary.from_dict(r) for r in data["regions"]),
                   tuple(ContactSummary.from_dict(c) for c in data["contacts"]),
                   tuple(InterfaceSummary.from_dict(i) for i in data["interfaces"]))
