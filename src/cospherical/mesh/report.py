"""The report of a meshed octree: sizes, the exact checks, and the frequency-weighted statistics.

The report is made of figures that add up: :func:`mesh_figures` measures one mesh,
or one piece of a partitioned mesh, and :func:`merged_report` adds the pieces' figures
up (pairing the faces left open at the seams) into the report of the whole.  A
mesh in one piece goes the same way (:func:`mesh_report`), so the two cannot drift apart.
"""

from __future__ import annotations

import copy
from collections import Counter
from dataclasses import dataclass, field, fields
from fractions import Fraction
from typing import Any, Callable, Iterable, Mapping, NamedTuple, Sequence

import numpy as np
from numpy.typing import NDArray

from ..catalogue import Catalogue
from ..version import __version__
from .assembly import Mesh
from .checks import (DelaunayCheck, OpenFaces, check_circumcenters, check_conformity, check_delaunay, check_volume,
                     match_seams)
from .tree import Octree
from .statistics import level_counts, occurrences, statistics, uniform_study

__all__ = ["CheckedReport", "MeshFigures", "MeshReport", "checked_mesh_report", "merged_report", "mesh_figures", "mesh_report",
           "outside_catalogue"]

# Figures of the pieces that the whole's report adds up.
_SUMMED = ("flat_elements", "nonconforming_faces", "interior_faces", "boundary_faces", "circumcenters_outside_leaf",
           "leaves_not_fvm_adequate", "elements_not_cospherical", "boundary_circumcenters_outside",
           "delaunay_violations", "delaunay_violating_pairs", "delaunay_violating_leaves", "delaunay_ties",
           "delaunay_exact_tests", "delaunay_violating_fvm_leaves", "leaves_tessellated_on_the_fly",
           "cells_spanning_leaves", "delaunay_spheres_bounded")


def outside_catalogue(mesh: Mesh) -> list[dict[str, Any]]:
    """The element types of the mesh its catalogue (:attr:`Mesh.catalogue`) does not name: id, systematic name, count, one example.

    The example is one element's vertices in domain units (exact fractions of the
    domain's sides, as text).  Nothing is added to the catalogue.
    """
    known = mesh.catalogue
    found: dict[str, dict[str, Any]] = {}
    if all(type_id in known for _, type_id in mesh.block_types()):  # the common case: no vertex ids gathered
        return []
    for rows, nodes, _, type_id in mesh.blocks():
        if type_id is None or type_id in known or not len(rows):  # a mesh's blocks all have types
            continue
        entry = found.setdefault(type_id, {"id": type_id, "name": mesh.types.get(type_id, {}).get("name", type_id),
                                           "count": 0, "example": None})
        entry["count"] += int(len(rows))
        if entry["example"] is None:
            entry["example"] = [[str(Fraction(int(x), mesh.grid)) for x in mesh.vertices[v]] for v in nodes[0]]
    return sorted(found.values(), key=lambda e: (-e["count"], e["id"]))


class MeshFigures(NamedTuple):
    """What :func:`mesh_figures` measured on a mesh (or on one piece of a partitioned mesh).

    ``figures``: every count and check as the report names them, figures that add up over
    pieces (:func:`merged_report` reads them); ``delaunay``: the global Delaunay check
    (``None`` when skipped); ``open_faces``: the faces a piece leaves open at its seams, when
    asked (see :func:`~cospherical.mesh.checks.check_conformity`).
    """

    figures: dict[str, Any]
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

    figures = {"elements": len(mesh), "types_outside_catalogue": outside_catalogue(mesh),
               "cells_spanning_leaves": int(mesh.cells.spanning.sum()) if mesh.cells is not None else 0}
    start("volume")
    volume = check_volume(mesh)
    figures.update(volume=volume.volume, flat_elements=volume.flat_elements)
    start("conformity")
    conformity = check_conformity(mesh, open_faces=open_faces, progress=conformity_progress)
    figures.update(conformity.figures())
    start("circumcenters")
    figures.update(check_circumcenters(mesh).figures())
    found = None
    if delaunay:
        start("delaunay")
        found = checked if checked is not None else check_delaunay(mesh, progress=progress)
        figures.update(found.figures())
        # the point of counting them: a leaf can be fvm_adequate on its own and still not globally Delaunay
        fvm = np.array([p.fvm_adequate for p in mesh.tessellations],
                       dtype=bool)[mesh.leaf_tessellation[found.violating_leaf_ids]]
        figures["delaunay_violating_fvm_leaves"] = int(fvm.sum())
        figures["delaunay_spheres_bounded"] = found.bounded
    start("statistics")
    figures["type_counts"], figures["configurations"] = occurrences(mesh)
    kept = {p.code for _, p, _ in mesh.groups()}
    figures["mapped"] = sorted(p.code for p in mesh.tessellations if p.mapped_from is not None and p.code in kept)
    figures["leaves_tessellated_on_the_fly"] = int(sum(
        len(leaves) for _, p, leaves in mesh.groups(all_leaves=True) if p.on_the_fly))
    figures["types"] = dict(mesh.types)
    return MeshFigures(figures, found, conformity.open_faces)


def merged_report(tree: Octree, vertices: int, parts: Sequence[Mapping[str, Any]], described: Mapping[str, Any],
                  patterns: str | None, criterion: str = "optimal", uniform: bool = True, delaunay: bool = True,
                  leaf_mesh: Mapping[str, int] | None = None, cells: tuple[int, int] = (0, 0),
                  seams: Iterable[OpenFaces] | None = None,
                  vertex_points: Callable[[NDArray[np.int64]], NDArray[np.int64]] | None = None, grid: int = 1, *,
                  catalogue: Catalogue, domain_share: Fraction = Fraction(1),
                  uniform_computed: bool = False) -> dict[str, Any]:
    """The report of a mesh from the :func:`mesh_figures` of its pieces (one piece: the whole mesh).

    ``catalogue``: the element catalogue the pieces were assembled with (it names the types).

    ``cells``: the clusters re-tessellated (the report keeps its keys ``regions_retessellated`` and ``largest_region_vertices``) and the largest one's vertices; ``seams``:
    the faces the pieces left open, paired here (``vertex_points(ids)`` gives their
    grid points, for the examples).  ``domain_share``: the domain's volume as a fraction of the
    root box's (a device's boxes can leave part of their bounding box out).  ``uniform_computed``: the uniform
    study run even for a box whose figures ship precomputed (see :func:`~cospherical.mesh.statistics.uniform_study`).
    """
    summed = {key: sum(part[key] for part in parts) for key in _SUMMED if all(key in part for part in parts)}
    report: dict[str, Any] = {
        "schema_version": 1,
        "generator": f"cospherical {__version__}",
        "domain": list(tree.box.texts),
        "tree": described,
        "patterns": patterns,
        "criterion": criterion,
        "leaves": len(tree),
        "leaves_per_level": level_counts(tree),
        "vertices": int(vertices),
        "elements": sum(part["elements"] for part in parts),
    }
    type_counts: Counter[str] = sum((Counter(part["type_counts"]) for part in parts), Counter())
    outside: dict[str, dict[str, Any]] = {}
    for part in parts:
        for entry in part["types_outside_catalogue"]:
            mine = outside.setdefault(entry["id"], {**entry, "count": 0})
            mine["count"] += entry["count"]
    report.update({
        "types": len(type_counts),
        "delaunay_mode": "leaf" if leaf_mesh is None else "global",
        "leaf_mesh": leaf_mesh,
        "cells_spanning_leaves": summed["cells_spanning_leaves"],
        "regions_retessellated": cells[0],
        "largest_region_vertices": cells[1],
        "types_outside_catalogue": sorted(outside.values(), key=lambda e: (-e["count"], e["id"])),
    })
    volume = sum((part["volume"] for part in parts), Fraction(0))
    report.update({"volume_ok": volume == domain_share and summed["flat_elements"] == 0, "volume": str(volume),
                   "flat_elements": summed["flat_elements"]})
    examples = [e for part in parts for e in part["nonconforming_examples"]]
    conformity = {key: summed[key] for key in ("nonconforming_faces", "interior_faces", "boundary_faces")}
    if seams is not None:
        if vertex_points is None:
            raise ValueError("merged_report: seams without vertex_points, which places their faces")
        matched = match_seams(seams, vertex_points, grid)
        conformity["nonconforming_faces"] += matched.nonconforming_faces
        conformity["interior_faces"] += matched.interior_faces
        examples += matched.nonconforming_examples
    report.update(conformity, nonconforming_examples=examples[:5])
    report.update({key: summed[key] for key in ("circumcenters_outside_leaf", "leaves_not_fvm_adequate",
                                                "elements_not_cospherical", "boundary_circumcenters_outside")})
    if delaunay:
        report.update({key: summed[key] for key in ("delaunay_violations", "delaunay_violating_pairs",
                                                    "delaunay_violating_leaves", "delaunay_ties",
                                                    "delaunay_exact_tests", "delaunay_violating_fvm_leaves")})
    else:
        report["delaunay_violations"] = None
    configurations: dict[str, dict[str, Any]] = {}
    for part in parts:
        for code, entry in part["configurations"].items():
            mine = configurations.setdefault(code, {**entry, "leaves": 0})
            mine["leaves"] += entry["leaves"]
    on_the_fly = sum(c["tessellated_on_the_fly"] for c in configurations.values())
    mapped = len({code for part in parts for code in part["mapped"]})
    report["configurations"] = len(configurations)
    report["configurations_from_table"] = len(configurations) - on_the_fly - mapped
    report["configurations_mapped"] = mapped
    report["tessellated_on_the_fly"] = on_the_fly
    report["leaves_tessellated_on_the_fly"] = summed["leaves_tessellated_on_the_fly"]
    types: dict[str, dict[str, Any]] = {}
    for part in parts:
        types.update(part["types"])
    report.update(statistics(type_counts, configurations, len(tree), types, catalogue,
                             uniform_study(tree.box, catalogue, uniform_computed) if uniform else None))
    report["checks"] = _checks_run(patterns is not None, delaunay, summed)
    return report


def _checks_run(table: bool, delaunay: bool, summed: Mapping[str, int]) -> dict[str, Any]:
    """The report's ``checks``: which exact checks ran, which did not and why, and how the Delaunay check
    found the vertices near each sphere (bounded by the tree's structure; the others searched)."""
    checks: dict[str, Any] = {"run": (["table_entries"] if table else [])
                              + ["volume", "conformity", "circumcenters"] + (["delaunay"] if delaunay else [])}
    if delaunay:
        # the others are searched (a piece searches its share of the cells and their surroundings: not a
        # figure that adds up to the whole's)
        checks["delaunay_spheres"] = {"bounded_by_the_tree": summed.get("delaunay_spheres_bounded", 0)}
    else:
        checks["not_run"] = {"delaunay": "not asked for (--no-delaunay): delaunay_violations is null"}
    return checks


@dataclass(frozen=True)
class CheckedReport:
    """A mesh's report and the global Delaunay check behind it.

    Attributes
    ----------
    report : dict
        The report (the keys of ``schemas/mesh-report.schema.json``, as :func:`mesh_report` gives it).
    delaunay : DelaunayCheck or None
        What the exact global Delaunay check found (its elements give the ``delaunay_ok`` cell
        data); ``None`` when the check was skipped.
    """

    report: dict[str, Any]
    delaunay: DelaunayCheck | None


def mesh_report(mesh: Mesh, tree: Mapping[str, Any], patterns: str | None, criterion: str = "optimal",
                uniform: bool = True, delaunay: bool = True, stage: Callable[[str], None] | None = None,
                progress: Callable[[int], None] | None = None,
                leaf_mesh: Mapping[str, int] | None = None, checked: DelaunayCheck | None = None) -> dict[str, Any]:
    """Run every check on ``mesh`` and gather the report (the keys of ``schemas/mesh-report.schema.json``).

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
    >>> report = mesh_report(assemble(tree), {"source": "refine"}, None, uniform=False)
    >>> [report[k] for k in ("leaves", "elements", "volume_ok", "nonconforming_faces", "delaunay_violations")]
    [15, 48, True, 0, 0]
    """
    return checked_mesh_report(mesh, tree, patterns, criterion, uniform, delaunay, stage, progress, leaf_mesh,
                               checked).report


def checked_mesh_report(mesh: Mesh, tree: Mapping[str, Any], patterns: str | None, criterion: str = "optimal",
                        uniform: bool = True, delaunay: bool = True, stage: Callable[[str], None] | None = None,
                        progress: Callable[[int], None] | None = None, leaf_mesh: Mapping[str, int] | None = None,
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
    Counts are ``int``; the nested figures (``tree``, ``leaf_mesh``, the frequency
    tables, ``dual``) are the report's own JSON values, read-only by convention.
    ``delaunay_violations`` is ``None`` when the global Delaunay check was skipped;
    the fields that default to ``None`` are absent from the JSON when not computed.
    ``timings``: seconds per stage of the run (``tree``, ``assembly``, ``volume``, ...,
    ``dual``), not part of ``report.json`` (a rerun's file is byte-identical).
    """

    schema_version: int
    generator: str
    domain: tuple[str, str, str]
    tree: Mapping[str, Any]
    patterns: str | None
    criterion: str
    leaves: int
    leaves_per_level: Mapping[str, int]
    vertices: int
    elements: int
    types: int
    delaunay_mode: str
    leaf_mesh: Mapping[str, Any] | None
    cells_spanning_leaves: int
    regions_retessellated: int
    largest_region_vertices: int
    types_outside_catalogue: list[dict[str, Any]]
    volume_ok: bool
    volume: str
    flat_elements: int
    nonconforming_faces: int
    interior_faces: int
    boundary_faces: int
    nonconforming_examples: list[list[list[float]]]
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
    type_frequencies: list[dict[str, Any]] = field(default_factory=list)
    configuration_frequencies: list[dict[str, Any]] = field(default_factory=list)
    uniform: Mapping[str, Any] | None = None
    negative_coefficients: Mapping[str, int] | None = None
    dual: Mapping[str, Any] | None = None
    device: Mapping[str, Any] | None = None
    checks: Mapping[str, Any] | None = None
    timings: Mapping[str, float] = field(default_factory=dict, compare=False)

    def to_dict(self) -> dict[str, Any]:
        """The report as ``report.json`` holds it (a new dict, deep-copied: changing it changes nothing here)."""
        result: dict[str, Any] = {}
        for item in fields(self):
            value = getattr(self, item.name)
            if item.name == "timings" or (value is None and item.name in _ABSENT_WHEN_NONE):
                continue
            result[item.name] = list(value) if item.name == "domain" else copy.deepcopy(value)
        return result

    @classmethod
    def from_dict(cls, report: Mapping[str, Any], timings: Mapping[str, float] | None = None) -> "MeshReport":
        """The report of a ``report.json`` object (or :func:`mesh_report`'s dict); an unknown key raises ``TypeError``."""
        values = {key: value for key, value in report.items()}
        values["domain"] = tuple(values["domain"])
        return cls(**values, timings=dict(timings or {}))
