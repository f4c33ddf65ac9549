"""The report of a meshed octree: sizes, the exact checks, and the frequency-weighted statistics."""

from __future__ import annotations

from fractions import Fraction
from typing import Callable

import numpy as np

from ..catalogue import shipped_catalogue
from ..version import __version__
from .assembly import Mesh
from .checks import check_circumcenters, check_conformity, check_delaunay, check_volume
from .statistics import level_counts, mesh_statistics, uniform_study

__all__ = ["mesh_report", "outside_catalogue"]


def outside_catalogue(mesh: Mesh) -> list[dict]:
    """The element types of the mesh the shipped catalogue does not name: id, systematic name, count, one example.

    The example is one element's vertices in domain units (exact fractions of the
    domain's sides, as text).  Nothing is added to the catalogue.
    """
    known = {entry["id"] for entry in shipped_catalogue()["types"]}
    found: dict[str, dict] = {}
    for rows, nodes, _, type_id in mesh.blocks():
        if type_id in known:
            continue
        entry = found.setdefault(type_id, {"id": type_id, "name": mesh.types.get(type_id, {}).get("name", type_id),
                                           "count": 0, "example": None})
        entry["count"] += int(len(rows))
        if entry["example"] is None:
            entry["example"] = [[str(Fraction(int(x), mesh.grid)) for x in mesh.vertices[v]] for v in nodes[0]]
    return sorted(found.values(), key=lambda e: (-e["count"], e["id"]))


def mesh_report(mesh: Mesh, tree: dict, patterns: str | None, criterion: str = "optimal", uniform: bool = True,
                delaunay: bool = True, stage: Callable[[str], None] | None = None,
                progress: Callable[[int], None] | None = None, violating: list | None = None,
                leaf_mesh: dict | None = None, checked: dict | None = None) -> dict:
    """Run every check on ``mesh`` and gather the report (the keys of ``schemas/mesh-report.schema.json``).

    ``tree`` describes where the octree came from; ``patterns`` names the table read
    (``None``: every configuration tessellated); ``uniform`` adds the uniform-weight
    bisection study of the box beside the mesh's frequencies; ``delaunay=False``
    skips the global Delaunay check (``delaunay_violations`` is then ``null``);
    ``stage(name)`` is told as each check starts, ``progress(n)`` as the Delaunay check
    goes through the elements; ``violating``, a list, receives the array of the elements
    whose sphere strictly holds a vertex (for the ``delaunay_ok`` cell data).
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
    def start(name: str) -> None:
        if stage:
            stage(name)

    report = {
        "schema_version": 1,
        "generator": f"cospherical {__version__}",
        "domain": list(mesh.box.texts),
        "tree": tree,
        "patterns": patterns,
        "criterion": criterion,
        "leaves": len(mesh.tree),
        "leaves_per_level": level_counts(mesh),
        "vertices": int(len(mesh.vertices)),
        "elements": len(mesh),
        "types": len(mesh.element_types()[0]),
        "delaunay_mode": "leaf" if leaf_mesh is None else "global",
        "leaf_mesh": leaf_mesh,
        "cells_spanning_leaves": int(mesh.cells.spanning.sum()) if mesh.cells is not None else 0,
        "regions_retessellated": mesh.cells.regions if mesh.cells is not None else 0,
        "largest_region_vertices": mesh.cells.largest_region if mesh.cells is not None else 0,
        "types_outside_catalogue": outside_catalogue(mesh),
    }
    start("volume")
    report.update(check_volume(mesh))
    start("conformity")
    report.update(check_conformity(mesh))
    start("circumcenters")
    report.update(check_circumcenters(mesh))
    if delaunay:
        start("delaunay")
        found = dict(checked) if checked is not None else check_delaunay(mesh, progress=progress)
        bad_leaves = found.pop("_leaves")
        bad_elements = found.pop("_elements")
        found.pop("_not_cells")
        if violating is not None:
            violating.append(bad_elements)
        report.update(found)
        # the point: a leaf can be fvm_adequate on its own and still not globally Delaunay
        fvm = np.array([p.fvm_adequate for p in mesh.patterns], dtype=bool)[mesh.leaf_pattern[bad_leaves]]
        report["delaunay_violating_fvm_leaves"] = int(fvm.sum())
    else:
        report["delaunay_violations"] = None
    on_the_fly = [p for _, p, _ in mesh.groups(all_leaves=True) if p.on_the_fly]
    report["configurations"] = len(mesh.patterns)
    mapped = sum(p.mapped_from is not None for _, p, _ in mesh.groups())
    report["configurations_from_table"] = len(mesh.patterns) - len(on_the_fly) - mapped
    report["configurations_mapped"] = mapped
    report["tessellated_on_the_fly"] = len(on_the_fly)
    report["leaves_tessellated_on_the_fly"] = int(sum(
        len(leaves) for _, p, leaves in mesh.groups(all_leaves=True) if p.on_the_fly))
    start("statistics")
    report.update(mesh_statistics(mesh, uniform_study(mesh.box) if uniform else None))
    return report
