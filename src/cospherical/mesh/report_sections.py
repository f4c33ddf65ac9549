"""The sections of a mesh's report, typed: what :class:`~cospherical.mesh.report.MeshReport` holds beside its counts.

Each section is a frozen dataclass whose fields are the keys of its object in
``report.json`` (``schemas/mesh-report.schema.json``), in the order the file writes
them: ``to_dict()`` gives that object (a new one, plain lists and dicts), ``from_dict()``
reads it back.  Sequences are tuples, so a report cannot be changed once made; what
is keyed by open-ended names (a check not run and why; leaves per level; seconds per
stage) is a read-only mapping (:class:`ReadOnlyMapping`).

The module imports nothing of the mesher, so the modules that measure a section
(the checks, the statistics, the dual, a device's regions) make it typed and the
report only gathers them.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import TYPE_CHECKING, Any, ClassVar, Iterator, Mapping, TypeVar, cast

from ..lazy import on_first_use

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

    from ._dual_device_sections import (ContactSummary, DeviceSummary, DualSummary, InterfaceSummary, MixedCounts,
                                        NegativeCoefficients, RegionSummary, TetrahedralCounts)

__all__ = ["ChecksSummary", "ConfigurationFrequency", "ContactSummary", "DelaunaySpheres", "DeviceSummary",
           "DualSummary", "InterfaceSummary", "LeafMeshSummary", "MixedCounts", "NegativeCoefficients",
           "OutsideType", "ReadOnlyMapping", "RegionSummary", "TetrahedralCounts", "TreeSummary", "TypeFrequency",
           "UniformSummary", "plain", "read_only"]

# The sections only --dual and a device write, made when first asked for (see __getattr__)
_DUAL_AND_DEVICE = frozenset({"ContactSummary", "DeviceSummary", "DualSummary", "InterfaceSummary", "MixedCounts",
                              "NegativeCoefficients", "RegionSummary", "TetrahedralCounts"})


# A mesh without a dual or a device never makes these eight dataclasses (~4 ms at start-up); their names stay
# this module's: `from cospherical.mesh.report_sections import DualSummary` loads them.
__getattr__ = on_first_use(globals(), dict.fromkeys(_DUAL_AND_DEVICE, f"{__package__}._dual_device_sections"))


K = TypeVar("K")
V = TypeVar("V")


def plain(value: Any) -> Any:
    """``value`` as JSON holds it: a section as its ``to_dict()``, tuples as lists, mappings as new dicts."""
    if isinstance(value, _Section):
        return value.to_dict()
    if isinstance(value, (tuple, list)):
        return [plain(item) for item in value]
    if isinstance(value, Mapping):
        return {key: plain(item) for key, item in value.items()}
    return value


class ReadOnlyMapping(Mapping[K, V]):
    """A mapping that cannot be changed: a copy of the one it was made from, in its order.

    :class:`types.MappingProxyType` is read-only too but cannot be pickled, and reports and
    a partitioned mesh's figures travel between processes.  Equal to any mapping of the
    same items (a dict included).
    """

    __slots__ = ("_items",)

    def __init__(self, items: Mapping[K, V]) -> None:
        self._items = dict(items)

    def __getitem__(self, key: K) -> V:
        return self._items[key]

    def __iter__(self) -> Iterator[K]:
        return iter(self._items)

    def __len__(self) -> int:
        return len(self._items)

    def __repr__(self) -> str:
        return f"ReadOnlyMapping({self._items!r})"

    def __reduce__(self) -> tuple[type[ReadOnlyMapping[K, V]], tuple[dict[K, V]]]:
        return type(self), (self._items,)


def read_only(mapping: Mapping[K, V]) -> ReadOnlyMapping[K, V]:
    """A read-only copy of ``mapping`` (changing the original changes nothing in it)."""
    return ReadOnlyMapping(mapping)


class _Section:
    """A report section's ``to_dict()``: its fields in order, those in ``_ABSENT_WHEN_NONE`` left out when ``None``."""

    _ABSENT_WHEN_NONE: ClassVar[frozenset[str]] = frozenset()

    def to_dict(self) -> dict[str, Any]:
        """The section as ``report.json`` holds it (a new object: changing it changes nothing here)."""
        result: dict[str, Any] = {}
        for item in fields(cast("DataclassInstance", self)):
            value = getattr(self, item.name)
            if value is None and item.name in self._ABSENT_WHEN_NONE:
                continue
            result[item.name] = plain(value)
        return result


def _only_fields(section: type[_Section], data: Mapping[str, Any]) -> Mapping[str, Any]:
    """``data``, refused (``TypeError``, as a constructor refuses an unknown keyword) if it has a key ``section`` lacks."""
    known = {item.name for item in fields(cast("type[DataclassInstance]", section))}
    unknown = sorted(set(data) - known)
    if unknown:
        raise TypeError(f"{section.__name__}: unknown key {unknown[0]!r}")
    return data


def _strings(values: Any) -> tuple[str, ...]:
    return tuple(str(v) for v in values)


@dataclass(frozen=True)
class TreeSummary(_Section):
    """Where the octree came from (``report.json``'s ``tree``); the fields that do not apply are ``None`` (absent).

    Attributes
    ----------
    source : str
        ``refine`` (refined at shapes), ``leaves`` (a leaf list, or a tree given as it is) or ``device``.
    device : str or None
        The device's name (``source == "device"``).
    file : str or None
        The leaf list's file name, when it came from a file.
    levels : int or None
        The refinement's deepest level asked for.
    refine : tuple of str or None
        The refinement shapes, as text (``sphere:0.5,0.5,0.5,0.3``).
    balance : str or None
        ``vertex`` or ``edge``: which neighbours the 2:1 balance holds across.
    resolving_level : int or None
        A device's level at which every box boundary lies on leaf faces.
    depth : int or None
        The tree's deepest leaf level.
    """

    _ABSENT_WHEN_NONE: ClassVar[frozenset[str]] = frozenset({"device", "file", "levels", "refine", "balance",
                                                             "resolving_level", "depth"})

    source: str
    device: str | None = None
    file: str | None = None
    levels: int | None = None
    refine: tuple[str, ...] | None = None
    balance: str | None = None
    resolving_level: int | None = None
    depth: int | None = None

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> TreeSummary:
        """The section of a ``report.json`` ``tree`` object."""
        return cls(**{**data, **({"refine": _strings(data["refine"])} if "refine" in data else {})})


@dataclass(frozen=True)
class LeafMeshSummary(_Section):
    """What the exact check found on the leaf mesh before the global Delaunay step re-tessellated it (``leaf_mesh``).

    Attributes
    ----------
    elements : int
        The leaf mesh's elements.
    delaunay_violations : int
        Its elements whose circumsphere strictly holds a vertex.
    delaunay_ties : int
        Vertices found exactly on an element's circumsphere.
    elements_replaced : int
        Its elements that are not cells of the Delaunay subdivision (re-tessellated).
    fallback : str or None
        Why the leaf mesh was kept instead (a device whose regions' subdivisions do not meet
        face to face); ``None`` (absent) when the subdivision was kept.
    """

    _ABSENT_WHEN_NONE: ClassVar[frozenset[str]] = frozenset({"fallback"})

    elements: int
    delaunay_violations: int
    delaunay_ties: int
    elements_replaced: int
    fallback: str | None = None

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> LeafMeshSummary:
        """The section of a ``report.json`` ``leaf_mesh`` object."""
        return cls(**data)

    def __add__(self, other: LeafMeshSummary) -> LeafMeshSummary:
        """The figures of two pieces of a leaf mesh, added up (neither fell back)."""
        return LeafMeshSummary(self.elements + other.elements, self.delaunay_violations + other.delaunay_violations,
                               self.delaunay_ties + other.delaunay_ties, self.elements_replaced + other.elements_replaced)


@dataclass(frozen=True)
class OutsideType(_Section):
    """An element type of the mesh its catalogue does not name (``types_outside_catalogue``).

    Attributes
    ----------
    id : str
        The type's id.
    name : str
        Its systematic name.
    count : int
        Its elements in the mesh.
    example : tuple of tuple of str
        One element's vertices, each three exact fractions of the domain's sides (text).
    """

    id: str
    name: str
    count: int
    example: tuple[tuple[str, ...], ...]

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> OutsideType:
        """The entry of a ``report.json`` ``types_outside_catalogue`` list."""
        data = _only_fields(cls, data)
        return cls(data["id"], data["name"], data["count"], tuple(_strings(point) for point in data["example"]))


@dataclass(frozen=True)
class TypeFrequency(_Section):
    """How often an element type occurs in the mesh, beside the uniform bisection study (``type_frequencies``).

    Attributes
    ----------
    id : str
        The type's id.
    name : str
        Its name (the catalogue's, else the systematic one).
    paper_class : str or None
        The paper's class of the type, if it has one.
    vtk : str or None
        The VTK cell it is written as (``None``: a polyhedron).
    count : int
        Its elements in the mesh.
    share : float
        ``count`` over the mesh's elements (rounded to 6 digits).
    uniform_count : int or None
        Its elements in the uniform study (``None`` without the study).
    uniform_share : float or None
        Its share there (``None`` without the study).
    """

    id: str
    name: str
    paper_class: str | None
    vtk: str | None
    count: int
    share: float
    uniform_count: int | None
    uniform_share: float | None

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> TypeFrequency:
        """The entry of a ``report.json`` ``type_frequencies`` list."""
        return cls(**data)


@dataclass(frozen=True)
class ConfigurationFrequency(_Section):
    """How often a leaf configuration occurs in the mesh (``configuration_frequencies``).

    Attributes
    ----------
    code : str
        The configuration's whole point-set code (edge digits, ``+f`` and its faces).
    leaves : int
        Its leaves in the mesh.
    share : float
        ``leaves`` over the tree's leaves (rounded to 6 digits).
    uniform_share : float or None
        Its weight in the uniform bisection study (one of 4,096), ``None`` outside that family.
    elements_per_leaf : int
        Its elements.
    fvm_adequate : bool
        Whether every circumcenter of its elements lies in the closed leaf.
    tessellated_on_the_fly : bool
        Whether the table lacked it and it was tessellated here.
    """

    code: str
    leaves: int
    share: float
    uniform_share: float | None
    elements_per_leaf: int
    fvm_adequate: bool
    tessellated_on_the_fly: bool

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ConfigurationFrequency:
        """The entry of a ``report.json`` ``configuration_frequencies`` list."""
        return cls(**data)


@dataclass(frozen=True)
class UniformSummary(_Section):
    """The uniform-weight bisection study the frequencies are set beside (``uniform``).

    Attributes
    ----------
    study : str
        ``bisection``: every configuration of one bisected edge set weighs the same.
    face_points : str
        ``octree``: the face-point policy of the study.
    configurations : int
        The study's configurations (4,096).
    elements : int
        Its elements, all configurations together.
    paper_final_share : float
        The share of them that are one of the paper's seven final elements.
    """

    study: str
    face_points: str
    configurations: int
    elements: int
    paper_final_share: float

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> UniformSummary:
        """The section of a ``report.json`` ``uniform`` object."""
        return cls(**data)


@dataclass(frozen=True)
class DelaunaySpheres(_Section):
    """How the Delaunay check found the vertices near each sphere (``checks.delaunay_spheres``).

    Attributes
    ----------
    bounded_by_the_tree : int
        Spheres whose nearby vertices the tree's structure bounded (the others were searched).
    """

    bounded_by_the_tree: int

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> DelaunaySpheres:
        """The section of a ``report.json`` ``checks.delaunay_spheres`` object."""
        return cls(**data)


@dataclass(frozen=True)
class ChecksSummary(_Section):
    """Which exact checks ran and which did not (``checks``).

    Attributes
    ----------
    run : tuple of str
        The checks run, in order: ``table_entries`` (a pattern table was read), ``volume``,
        ``conformity``, ``circumcenters``, ``delaunay``.
    delaunay_spheres : DelaunaySpheres or None
        With the Delaunay check: how it found each sphere's vertices (``None``, absent, without).
    not_run : Mapping of str to str or None
        The checks not run, each with why (open-ended: keyed by check name; read-only);
        ``None`` (absent) when every check ran.
    """

    _ABSENT_WHEN_NONE: ClassVar[frozenset[str]] = frozenset({"delaunay_spheres", "not_run"})

    run: tuple[str, ...]
    delaunay_spheres: DelaunaySpheres | None = None
    not_run: Mapping[str, str] | None = None

    def not_running(self, name: str, why: str) -> ChecksSummary:
        """The same summary with check ``name`` (if it is in :attr:`run`) not run, for the reason ``why``."""
        if name not in self.run:
            return self
        return replace(self, run=tuple(check for check in self.run if check != name),
                       not_run=read_only({name: why, **(self.not_run or {})}))

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ChecksSummary:
        """The section of a ``report.json`` ``checks`` object."""
        spheres, not_run = _only_fields(cls, data).get("delaunay_spheres"), data.get("not_run")
        return cls(_strings(data["run"]), DelaunaySpheres.from_dict(spheres) if spheres is not None else None,
                   read_only(not_run) if not_run is not None else None)
