"""The report of a meshed octree: sizes, the exact checks, and the frequency-weighted statistics.

The report is made of figures that add up: :func:`mesh_figures` measures one mesh,
or one piece of a partitioned mesh, and :func:`merged_report` adds the pieces' figures
up (pairing the faces left open at the seams) into the report of the whole.  A
mesh in one piece goes the same way (:func:`mesh_report`), so the two cannot drift apart.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field, fields, replace
from fractions import Fraction
from typing import TYPE_CHECKING, Any, Callable, Iterable, Mapping, NamedTuple, Sequence

import numpy as np
from numpy.typing import NDArray

from ..catalogue import Catalogue
from ..choices import DelaunayMode
from ..lazy import on_first_use
from ..version import __version__
from .assembly import Mesh, MeshType
from .checks import (DelaunayCheck, OpenFaces, check_circumcenters, check_conformity, check_delaunay, check_volume,
                     match_seams)
from . import report_sections
from .report_sections import (ChecksSummary, ConfigurationFrequency, DelaunaySpheres, LeafMeshSummary, OutsideType,
                              TreeSummary, TypeFrequency, UniformSummary, plain, read_only)
from .statistics import ConfigurationOccurrence, level_counts, occurrences, statistics, uniform_study
from .tree import Octree

if TYPE_CHECKING:  # made where first asked for (report_sections' __getattr__); this module's names as well
    from ._dual_device_sections import (ContactSummary, DeviceSummary, DualSummary, InterfaceSummary, MixedCounts,
                                        NegativeCoefficients, RegionSummary, TetrahedralCounts)

__all__ = ["CheckedReport", "ChecksSummary", "ConfigurationFrequency", "ContactSummary", "DelaunaySpheres",
           "DeviceSummary", "DualSummary", "InterfaceSummary", "LeafMeshSummary", "MeshFigures", "MeshReport",
           "PieceFigures",
           "MixedCounts", "NegativeCoefficients", "OutsideType", "RegionSummary", "TetrahedralCounts", "TreeSummary",
           "TypeFrequency", "UniformSummary", "checked_mesh_report", "merged_report", "mesh_figures", "mesh_report",
           "outside_catalogue"]


# The dual's and a device's sections, exported here too, made where first asked for (see report_sections)
__getattr__ = on_first_use(globals(), dict.fromkeys(report_sections._DUAL_AND_DEVICE, report_sections.__name__))


# A nonconforming face: its vertices, each three fractions of the domain's sides (floats)
Example = tuple[tuple[float, ...], ...]

def outside_catalogue(mesh: Mesh) -> tuple[OutsideType, ...]:
    """The element types of the mesh its catalogue (:attr:`Mesh.catalogue`) does not name: id, systematic name, count, one example.

    The example is one element's vertices in domain units (exact fractions of the
    domain's sides, as text).  Nothing is added to the catalogue.
    """
    known = mesh.catalogue
    found: dict[str, OutsideType] = {}
    if all(type_id in known for _, type_id in mesh.block_types()):  # the common case: no vertex ids gathered
        return ()
    for rows, nodes, _, type_id in mesh.blocks():
        if type_id is None or type_id in known or not len(rows):  # a mesh's blocks all have types
            continue
        if type_id not in found:
            example = tuple(tuple(str(Fraction(int(x), mesh.grid)) for x in mesh.vertices[v]) for v in nodes[0])
            found[type_id] = OutsideType(type_id, mesh.type_name(type_id), 0, example)
        found[type_id] = replace(found[type_id], count=found[type_id].count + int(len(rows)))
    return _by_count(found.values())


def _by_count(types: Iterable[OutsideType]) -> tuple[OutsideType, ...]:
    return tuple(sorted(types, key=lambda e: (-e.count, e.id)))


@dataclass(frozen=True)
class PieceFigures:
    """Every count and check of a mesh, or of one piece of a partitioned mesh: figures that add up over pieces.

    :func:`merged_report` adds the pieces' up into the report of the whole; the fields
    named as the report's keys are those keys' figures for this piece.

    Attributes
    ----------
    elements, cells_spanning_leaves, flat_elements : int
        The piece's elements, its cells spanning several leaves, its flat elements.
    types_outside_catalogue : tuple of OutsideType
        Its element types the catalogue does not name.
    volume : Fraction
        Its elements' volume over the root box's.
    nonconforming_faces, interior_faces, boundary_faces : int
        Its faces (those left open at its seams, asked for, not counted).
    nonconforming_examples : tuple
        Up to five nonconforming faces, their vertices as fractions of the domain's sides.
    circumcenters_outside_leaf, leaves_not_fvm_adequate, elements_not_cospherical, boundary_circumcenters_outside : int
        What :func:`~cospherical.mesh.checks.check_circumcenters` counted.
    delaunay_violations, delaunay_violating_pairs, delaunay_violating_leaves, delaunay_ties, delaunay_exact_tests : int or None
        What the global Delaunay check counted (``None``: not run).
    delaunay_violating_fvm_leaves : int or None
        Violating leaves whose own circumcenters all lie in them.
    delaunay_spheres_bounded : int or None
        Spheres whose nearby vertices the tree's structure bounded (the others searched).
    type_counts : Mapping of str to int
        Elements per type id (read-only).
    configurations : Mapping of str to ConfigurationOccurrence
        Per configuration code its leaves and what it is (read-only).
    mapped : tuple of str
        The configurations carried back from a table's orbit representative.
    leaves_tessellated_on_the_fly : int
        Leaves whose configuration the table lacked.
    types : Mapping of str to MeshType
        What each type met is: name, paper class, VTK cell, vertices, faces (read-only).
    """

    elements: int
    types_outside_catalogue: tuple[OutsideType, ...]
    cells_spanning_leaves: int
    volume: Fraction
    flat_elements: int
    nonconforming_faces: int
    interior_faces: int
    boundary_faces: int
    nonconforming_examples: tuple[Example, ...]
    circumcenters_outside_leaf: int
    leaves_not_fvm_adequate: int
    elements_not_cospherical: int
    boundary_circumcenters_outside: int
    type_counts: Mapping[str, int]
    configurations: Mapping[str, ConfigurationOccurrence]
    mapped: tuple[str, ...]
    leaves_tessellated_on_the_fly: int
    types: Mapping[str, MeshType]
    delaunay_violations: int | None = None
    delaunay_violating_pairs: int | None = None
    delaunay_violating_leaves: int | None = None
    delaunay_ties: int | None = None
    delaunay_exact_tests: int | None = None
    delaunay_violating_fvm_leaves: int | None = None
    delaunay_spheres_bounded: int | None = None


class MeshFigures(NamedTuple):
    """What :func:`mesh_figures` measured on a mesh (or on one piece of a partitioned mesh).

    ``figures``: every count and check, figures that add up over pieces (:func:`merged_report`
    reads them); ``delaunay``: the global Delaunay check (``None`` when skipped);
    ``open_faces``: the faces a piece leaves open at its seams, when asked (see
    :func:`~cospherical.mesh.checks.check_conformity`).
    """

    figures: PieceFigures
    delaunay: DelaunayCheck | None
    open_faces: tuple[OpenFaces, ...]


def mesh_figures(mesh: Mesh, delaunay: bool = True, stage: Callable[[str], None] | None = None,
                 progress: Callable[[int], None] | None = None, checked: DelaunayCheck | None = None,
                 open_faces: bool = False, conformity_progress: Callable[[int], None] | None = None) -> MeshFigures:
    """Every exact check and count of ``mesh`` (or of one piece of a partitioned mesh), as figures that add up,
    and the global Delaunay check (``checked`` when the caller has it; ``None`` when ``delaunay`` is false).

    ``open_faces=True``: ``mesh`` is a piece, whose faces left open at its seams are returned,
    not counted (see :func:`~cospherical.mesh.checks.check_conformity`).  ``progress`` is told as the
    Delaunay check goes, ``conformity_progress`` as faces are paired.
    """
    def start(name: str) -> None:
        if stage:
            stage(name)

    outside = outside_catalogue(mesh)
    start("volume")
    volume = check_volume(mesh)
    start("conformity")
    conformity = check_conformity(mesh, open_faces=open_faces, progress=conformity_progress)
    start("circumcenters")
    circumcenters = check_circumcenters(mesh)
    found = None
    spheres: dict[str, int] = {}
    if delaunay:
        start("delaunay")
        found = checked if checked is not None else check_delaunay(mesh, progress=progress)
        # the point of counting them: a leaf can be fvm_adequate on its own and still not globally Delaunay
        fvm = np.array([p.fvm_adequate for p in mesh.tessellations],
                       dtype=bool)[mesh.leaf_tessellation[found.violating_leaf_ids]]
        spheres = {"delaunay_violations": found.violations, "delaunay_violating_pairs": found.violating_pairs,
                   "delaunay_violating_leaves": found.violating_leaves, "delaunay_ties": found.ties,
                   "delaunay_exact_tests": found.exact_tests, "delaunay_violating_fvm_leaves": int(fvm.sum()),
                   "delaunay_spheres_bounded": found.bounded}
    start("statistics")
    type_counts, configurations = occurrences(mesh)
    kept = {p.code for _, p, _ in mesh.groups()}
    figures = PieceFigures(
        elements=len(mesh), types_outside_catalogue=outside,
        cells_spanning_leaves=int(mesh.cells.spanning.sum()) if mesh.cells is not None else 0,
        volume=volume.volume, flat_elements=volume.flat_elements,
        nonconforming_faces=conformity.nonconforming_faces, interior_faces=conformity.interior_faces,
        boundary_faces=conformity.boundary_faces, nonconforming_examples=_examples(conformity.nonconforming_examples),
        circumcenters_outside_leaf=circumcenters.circumcenters_outside_leaf,
        leaves_not_fvm_adequate=circumcenters.leaves_not_fvm_adequate,
        elements_not_cospherical=circumcenters.elements_not_cospherical,
        boundary_circumcenters_outside=circumcenters.boundary_circumcenters_outside,
        type_counts=read_only(type_counts), configurations=read_only(configurations),
        mapped=tuple(sorted(p.code for p in mesh.tessellations if p.mapped_from is not None and p.code in kept)),
        leaves_tessellated_on_the_fly=int(sum(len(leaves) for _, p, leaves in mesh.groups(all_leaves=True)
                                              if p.on_the_fly)),
        types=read_only(mesh.types), **spheres)
    return MeshFigures(figures, found, conformity.open_faces)


def _examples(faces: Iterable[Iterable[Iterable[float]]]) -> tuple[Example, ...]:
    """Nonconforming faces as tuples (each its vertices, each three fractions of the domain's sides)."""
    return tuple(tuple(tuple(point) for point in face) for face in faces)


def _total(parts: Sequence[PieceFigures], name: str) -> int:
    """A count added up over the pieces (one the pieces all have)."""
    values = [getattr(part, name) for part in parts]
    if any(value is None for value in values):
        raise ValueError(f"merged_report: a piece without {name}")
    return int(sum(values))


def merged_report(tree: Octree, vertices: int, parts: Sequence[PieceFigures], described: TreeSummary,
                  patterns: str | None, criterion: str = "optimal", uniform: bool = True, delaunay: bool = True,
                  leaf_mesh: LeafMeshSummary | None = None, cells: tuple[int, int] = (0, 0),
                  seams: Iterable[OpenFaces] | None = None,
                  vertex_points: Callable[[NDArray[np.int64]], NDArray[np.int64]] | None = None, grid: int = 1, *,
                  catalogue: Catalogue, domain_share: Fraction = Fraction(1),
                  uniform_computed: bool = False) -> MeshReport:
    """The report of a mesh from the :func:`mesh_figures` of its pieces (one piece: the whole mesh).

    ``catalogue``: the element catalogue the pieces were assembled with (it names the types).

    ``cells``: the clusters re-tessellated (the report keeps its keys ``regions_retessellated`` and ``largest_region_vertices``) and the largest one's vertices; ``seams``:
    the faces the pieces left open, paired here (``vertex_points(ids)`` gives their
    grid points, for the examples).  ``domain_share``: the domain's volume as a fraction of the
    root box's (a device's boxes can leave part of their bounding box out).  ``uniform_computed``: the uniform
    study run even for a box whose figures ship precomputed (see :func:`~cospherical.mesh.statistics.uniform_study`).
    """
    type_counts: Counter[str] = sum((Counter(part.type_counts) for part in parts), Counter())
    outside: dict[str, OutsideType] = {}
    for part in parts:
        for entry in part.types_outside_catalogue:
            mine = outside.get(entry.id)
            outside[entry.id] = entry if mine is None else replace(mine, count=mine.count + entry.count)
    volume = sum((part.volume for part in parts), Fraction(0))
    examples = [e for part in parts for e in part.nonconforming_examples]
    nonconforming, interior = _total(parts, "nonconforming_faces"), _total(parts, "interior_faces")
    if seams is not None:
        if vertex_points is None:
            raise ValueError("merged_report: seams without vertex_points, which places their faces")
        matched = match_seams(seams, vertex_points, grid)
        nonconforming += matched.nonconforming_faces
        interior += matched.interior_faces
        examples += _examples(matched.nonconforming_examples)
    configurations: dict[str, ConfigurationOccurrence] = {}
    for part in parts:
        for code, occurrence in part.configurations.items():
            met = configurations.get(code)
            configurations[code] = occurrence if met is None else replace(met, leaves=met.leaves + occurrence.leaves)
    on_the_fly = sum(c.tessellated_on_the_fly for c in configurations.values())
    mapped = len({code for part in parts for code in part.mapped})
    types: dict[str, MeshType] = {}
    for part in parts:
        types.update(part.types)
    frequencies = statistics(type_counts, configurations, len(tree), types, catalogue,
                             uniform_study(tree.box, catalogue, uniform_computed) if uniform else None)

    def delaunay_figure(key: str) -> int | None:
        return _total(parts, key) if delaunay else None

    x, y, z = tree.box.texts
    return MeshReport(
        schema_version=1, generator=f"cospherical {__version__}", domain=(x, y, z), tree=described,
        patterns=patterns, criterion=criterion, leaves=len(tree), leaves_per_level=level_counts(tree),
        vertices=int(vertices), elements=_total(parts, "elements"), types=len(type_counts),
        delaunay_mode="leaf" if leaf_mesh is None else "global", leaf_mesh=leaf_mesh,
        cells_spanning_leaves=_total(parts, "cells_spanning_leaves"), regions_retessellated=cells[0],
        largest_region_vertices=cells[1], types_outside_catalogue=_by_count(outside.values()),
        volume_ok=volume == domain_share and _total(parts, "flat_elements") == 0, volume=str(volume),
        flat_elements=_total(parts, "flat_elements"), nonconforming_faces=nonconforming, interior_faces=interior,
        boundary_faces=_total(parts, "boundary_faces"), nonconforming_examples=tuple(examples[:5]),
        circumcenters_outside_leaf=_total(parts, "circumcenters_outside_leaf"),
        leaves_not_fvm_adequate=_total(parts, "leaves_not_fvm_adequate"),
        elements_not_cospherical=_total(parts, "elements_not_cospherical"),
        boundary_circumcenters_outside=_total(parts, "boundary_circumcenters_outside"),
        delaunay_violations=delaunay_figure("delaunay_violations"),
        delaunay_violating_pairs=delaunay_figure("delaunay_violating_pairs"),
        delaunay_violating_leaves=delaunay_figure("delaunay_violating_leaves"),
        delaunay_ties=delaunay_figure("delaunay_ties"), delaunay_exact_tests=delaunay_figure("delaunay_exact_tests"),
        delaunay_violating_fvm_leaves=delaunay_figure("delaunay_violating_fvm_leaves"),
        configurations=len(configurations), configurations_from_table=len(configurations) - on_the_fly - mapped,
        configurations_mapped=mapped, tessellated_on_the_fly=on_the_fly,
        leaves_tessellated_on_the_fly=_total(parts, "leaves_tessellated_on_the_fly"),
        paper_final_share=frequencies.paper_final_share,
        leaves_in_bisection_family=frequencies.leaves_in_bisection_family,
        type_frequencies=frequencies.type_frequencies, configuration_frequencies=frequencies.configuration_frequencies,
        uniform=frequencies.uniform, checks=_checks_run(patterns is not None, delaunay, parts))


def _checks_run(table: bool, delaunay: bool, parts: Sequence[PieceFigures]) -> ChecksSummary:
    """The report's ``checks``: which exact checks ran, which did not and why, and how the Delaunay check
    found the vertices near each sphere (bounded by the tree's structure; the others searched)."""
    run = (("table_entries",) if table else ()) + ("volume", "conformity", "circumcenters") \
        + (("delaunay",) if delaunay else ())
    if delaunay:
        # the others are searched (a piece searches its share of the cells and their surroundings: not a
        # figure that adds up to the whole's)
        return ChecksSummary(run, DelaunaySpheres(_total(parts, "delaunay_spheres_bounded")))
    return ChecksSummary(run, not_run=read_only({"delaunay": "not asked for (--no-delaunay): delaunay_violations is null"}))


@dataclass(frozen=True)
class CheckedReport:
    """A mesh's report and the global Delaunay check behind it.

    Attributes
    ----------
    report : MeshReport
        The report, as :func:`mesh_report` gives it.
    delaunay : DelaunayCheck or None
        What the exact global Delaunay check found (its elements give the ``delaunay_ok`` cell
        data); ``None`` when the check was skipped.
    """

    report: MeshReport
    delaunay: DelaunayCheck | None


def mesh_report(mesh: Mesh, tree: TreeSummary, patterns: str | None, criterion: str = "optimal",
                uniform: bool = True, delaunay: bool = True, stage: Callable[[str], None] | None = None,
                progress: Callable[[int], None] | None = None,
                leaf_mesh: LeafMeshSummary | None = None, checked: DelaunayCheck | None = None) -> MeshReport:
    """Run every check on ``mesh`` and gather the report (:class:`MeshReport`: ``to_dict()`` gives ``report.json``).

    ``tree`` describes where the octree came from; ``patterns`` names the table read
    (``None``: every configuration tessellated); ``uniform`` adds the uniform-weight
    bisection study of the box beside the mesh's frequencies; ``delaunay=False``
    skips the global Delaunay check (``delaunay_violations`` is then ``null``);
    ``stage(name)`` is told as each check starts, ``progress(n)`` as the Delaunay check
    goes through the elements (:func:`checked_mesh_report` gives the check too).
    ``leaf_mesh``: what :func:`~cospherical.mesh.delaunay.delaunay_mesh` found on the
    leaf mesh when ``mesh`` is its global Delaunay subdivision (``delaunay_mode`` is
    then ``global``, else ``leaf``); ``checked``: the result of
    :func:`~cospherical.mesh.checks.check_delaunay` on ``mesh`` when the caller has it.

    Examples
    --------
    >>> from cospherical.core.configuration import Box
    >>> from cospherical.mesh.assembly import assemble
    >>> from cospherical.mesh.octree import build_octree, parse_shape
    >>> tree = build_octree(Box.parse([1, 1, 1]), 2, [parse_shape("point:0.1,0.1,0.1")])
    >>> report = mesh_report(assemble(tree), TreeSummary("refine"), None, uniform=False)
    >>> report.leaves, report.elements, report.volume_ok, report.nonconforming_faces, report.delaunay_violations
    (15, 48, True, 0, 0)
    """
    return checked_mesh_report(mesh, tree, patterns, criterion, uniform, delaunay, stage, progress, leaf_mesh,
                               checked).report


def checked_mesh_report(mesh: Mesh, tree: TreeSummary, patterns: str | None, criterion: str = "optimal",
                        uniform: bool = True, delaunay: bool = True, stage: Callable[[str], None] | None = None,
                        progress: Callable[[int], None] | None = None, leaf_mesh: LeafMeshSummary | None = None,
                        checked: DelaunayCheck | None = None,
                        conformity_progress: Callable[[int], None] | None = None,
                        uniform_computed: bool = False) -> CheckedReport:
    """:func:`mesh_report` (the same arguments), and the global Delaunay check it ran or was given;
    ``conformity_progress`` is told as faces are paired; ``uniform_computed``: see :func:`merged_report`."""
    figures, found, _ = mesh_figures(mesh, delaunay, stage, progress, checked,
                                     conformity_progress=conformity_progress)
    cells = (mesh.cells.clusters, mesh.cells.largest_cluster) if mesh.cells is not None else (0, 0)
    report = merged_report(mesh.tree, len(mesh.vertices), [figures], tree, patterns, criterion, uniform, delaunay,
                           leaf_mesh, cells, catalogue=mesh.catalogue, domain_share=mesh.domain_share,
                           uniform_computed=uniform_computed)
    return CheckedReport(report, found)


# The report's keys that are left out, rather than written as null, when they were not computed:
# the details of the global Delaunay check (only with the check), the uniform study (only when asked)
# the dual's figures (only with the dual) and a device's regions and contacts (only for a device).
_ABSENT_WHEN_NONE = frozenset({"delaunay_violating_pairs", "delaunay_violating_leaves", "delaunay_ties",
                               "delaunay_exact_tests", "delaunay_violating_fvm_leaves", "uniform",
                               "negative_coefficients", "dual", "device", "checks"})


@dataclass(frozen=True)
class MeshReport:
    """What the mesher found on one mesh: its sizes, the exact checks, the frequencies, and the time each stage took.

    The fields are the keys of ``schemas/mesh-report.schema.json``, in the order
    ``report.json`` writes them; :meth:`to_dict` gives that JSON object exactly and
    :meth:`from_dict` reads it back (``MeshReport.from_dict(r.to_dict()) == r``).
    Counts are ``int``; the nested sections are frozen dataclasses of their own
    (:mod:`cospherical.mesh.report_sections`: ``tree`` a :class:`TreeSummary`,
    ``dual`` a :class:`DualSummary`, ``device`` a :class:`DeviceSummary`, ...), lists
    are tuples, and the two open-ended mappings (``leaves_per_level``, keyed by level;
    ``timings``, keyed by stage) are read-only: a report cannot be changed once made.
    ``delaunay_violations`` is ``None`` when the global Delaunay check was skipped;
    the fields that default to ``None`` are absent from the JSON when not computed.
    ``timings``: seconds per stage of the run (``tree``, ``assembly``, ``volume``, ...,
    ``dual``), not part of ``report.json`` (a rerun's file is byte-identical).
    """

    schema_version: int
    generator: str
    domain: tuple[str, str, str]
    tree: TreeSummary
    patterns: str | None
    criterion: str
    leaves: int
    leaves_per_level: Mapping[str, int]
    vertices: int
    elements: int
    types: int
    delaunay_mode: DelaunayMode
    leaf_mesh: LeafMeshSummary | None
    cells_spanning_leaves: int
    regions_retessellated: int
    largest_region_vertices: int
    types_outside_catalogue: tuple[OutsideType, ...]
    volume_ok: bool
    volume: str
    flat_elements: int
    nonconforming_faces: int
    interior_faces: int
    boundary_faces: int
    nonconforming_examples: tuple[Example, ...]
    circumcenters_outside_leaf: int
    leaves_not_fvm_adequate: int
    elements_not_cospherical: int
    boundary_circumcenters_outside: int
    delaunay_violations: int | None
    delaunay_violating_pairs: int | None = None
    delaunay_violating_leaves: int | None = None
    delaunay_ties: int | None = None
    delaunay_exact_tests: int | None = None
    delaunay_violating_fvm_leaves: int | None = None
    configurations: int = 0
    configurations_from_table: int = 0
    configurations_mapped: int = 0
    tessellated_on_the_fly: int = 0
    leaves_tessellated_on_the_fly: int = 0
    paper_final_share: float = 0.0
    leaves_in_bisection_family: int = 0
    type_frequencies: tuple[TypeFrequency, ...] = ()
    configuration_frequencies: tuple[ConfigurationFrequency, ...] = ()
    uniform: UniformSummary | None = None
    negative_coefficients: NegativeCoefficients | None = None
    dual: DualSummary | None = None
    device: DeviceSummary | None = None
    checks: ChecksSummary | None = None
    timings: Mapping[str, float] = field(default_factory=lambda: read_only({}), compare=False)

    def to_dict(self) -> dict[str, Any]:
        """The report as ``report.json`` holds it (a new object of plain dicts and lists: changing it changes nothing here)."""
        result: dict[str, Any] = {}
        for item in fields(self):
            value = getattr(self, item.name)
            if item.name == "timings" or (value is None and item.name in _ABSENT_WHEN_NONE):
                continue
            result[item.name] = plain(value)
        return result

    @classmethod
    def from_dict(cls, report: Mapping[str, Any], timings: Mapping[str, float] | None = None) -> MeshReport:
        """The report of a ``report.json`` object; an unknown key raises ``TypeError``."""
        values = dict(report)
        x, y, z = (str(v) for v in values["domain"])
        values["domain"] = (x, y, z)
        values["tree"] = TreeSummary.from_dict(values["tree"])
        values["leaves_per_level"] = read_only(values["leaves_per_level"])
        values["types_outside_catalogue"] = tuple(OutsideType.from_dict(t) for t in values["types_outside_catalogue"])
        values["nonconforming_examples"] = tuple(tuple(tuple(point) for point in face)
                                                 for face in values.get("nonconforming_examples", ()))
        for key, section in _SECTIONS.items():
            if values.get(key) is not None:
                values[key] = section(values[key])
        for key, entry in _ROWS.items():
            if key in values:
                values[key] = tuple(entry(row) for row in values[key])
        return cls(**values, timings=read_only(timings or {}))

    def with_timings(self, timings: Mapping[str, float]) -> MeshReport:
        """The same report with ``timings`` (seconds per stage, kept read-only)."""
        return replace(self, timings=read_only(timings))


# The report's sections that are objects, and those that are lists of rows: how each is read from JSON (the
# dual's and a device's sections looked up when read: report_sections makes them when first asked for)
_SECTIONS: dict[str, Callable[[Mapping[str, Any]], Any]] = {
    "leaf_mesh": LeafMeshSummary.from_dict, "uniform": UniformSummary.from_dict,
    "negative_coefficients": lambda data: report_sections.NegativeCoefficients.from_dict(data),
    "dual": lambda data: report_sections.DualSummary.from_dict(data),
    "device": lambda data: report_sections.DeviceSummary.from_dict(data), "checks": ChecksSummary.from_dict}
_ROWS: dict[str, Callable[[Mapping[str, Any]], Any]] = {
    "type_frequencies": TypeFrequency.from_dict, "configuration_frequencies": ConfigurationFrequency.from_dict}
