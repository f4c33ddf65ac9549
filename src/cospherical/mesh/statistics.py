"""What really occurs in a mesh: element types and configurations weighted by how often they occur.

The paper's study weighs every bisection configuration the same ("but this is for
sure not true ... a complete study should consider also this case").  Here each
type and configuration is counted over the leaves of a real octree, beside the
uniform-weight bisection study of the same box (octree point policy, the paper's
system), and the share of elements the paper's seven final elements cover.
"""

from __future__ import annotations

from collections import Counter
from typing import Any

import numpy as np

from ..catalogue import Catalogue
from ..core.configuration import Box, Configuration
from ..studies.engine import bisection_codes, run_study
from .assembly import PAPER_FINAL, Mesh, type_info
from .tree import Octree

__all__ = ["in_bisection_family", "level_counts", "mesh_statistics", "occurrences", "statistics", "uniform_study"]

_BISECTION_CONFIGURATIONS = 4096


def uniform_study(box: Box, catalogue: Catalogue) -> dict[str, Any]:
    """Element counts per type of the uniform-weight bisection study of ``box`` (octree policy, optimal),
    the types named by ``catalogue``."""
    study = run_study("bisection", box, bisection_codes(), "octree", criteria=("optimal",))
    counts = {tc.type.id: tc.count for tc in study.type_counts("optimal")}
    info = {tc.type.id: type_info(tc.type.id, tc.type, catalogue) for tc in study.type_counts("optimal")}
    return {"counts": counts, "types": info, "elements": study.total("optimal")}


def _share(part: int, whole: int) -> float:
    return round(part / whole, 6) if whole else 0.0


def in_bisection_family(configuration: Configuration) -> bool:
    """Whether a leaf's point set is one the paper's bisection study has (octree policy of its edge code).

    >>> in_bisection_family(Configuration.from_code("888888888888+f"))
    False
    >>> in_bisection_family(Configuration.from_code("800000000000+f"))
    True
    """
    code = configuration.point_set_code
    if code is None:  # a configuration without a point-set code is not one of the family's
        return False
    digits = code.split("+")[0]
    return Configuration.from_code(digits, configuration.box).point_set_code == configuration.point_set_code


def mesh_statistics(mesh: Mesh, uniform: dict[str, Any] | None = None) -> dict[str, Any]:
    """Per element type and per configuration, how often it occurs in the mesh, beside the uniform study.

    Returns ``type_frequencies`` (by decreasing count), ``configuration_frequencies``
    (by decreasing leaf count), ``paper_final_share`` (elements whose paper class is
    one of the paper's seven final elements) and, with ``uniform``, its figures.
    """
    type_counts, configurations = occurrences(mesh)
    return statistics(type_counts, configurations, len(mesh.tree), mesh.types, mesh.catalogue, uniform)


def occurrences(mesh: Mesh) -> tuple[Counter[str], dict[str, dict[str, Any]]]:
    """Elements per type id, and per configuration code its leaves (replaced ones too) and what it is.

    Both add up over the pieces of a partitioned mesh (leaves summed per code).
    """
    type_counts: Counter[str] = Counter()
    for rows, type_id in mesh.block_types():
        if len(rows):
            type_counts[type_id] += len(rows)
    configurations: dict[str, dict[str, Any]] = {}
    for _, tessellation, leaves in mesh.groups(all_leaves=True):
        configurations[tessellation.code] = {
            "code": tessellation.code,
            "leaves": int(len(leaves)),
            "in_bisection_family": in_bisection_family(tessellation.configuration),
            "elements_per_leaf": len(tessellation.elements),
            "fvm_adequate": tessellation.fvm_adequate,
            "tessellated_on_the_fly": tessellation.on_the_fly,
        }
    return type_counts, configurations


def statistics(type_counts: Counter[str], configurations: dict[str, dict[str, Any]], total_leaves: int,
               types: dict[str, dict[str, Any]], catalogue: Catalogue,
               uniform: dict[str, Any] | None = None) -> dict[str, Any]:
    """:func:`mesh_statistics` from the :func:`occurrences` of a mesh (or of all its pieces, added up);
    ``catalogue`` names the types met nowhere else."""
    frequencies = sorted(({
        "code": c["code"], "leaves": c["leaves"], "share": _share(c["leaves"], total_leaves),
        "uniform_share": _share(1, _BISECTION_CONFIGURATIONS) if c["in_bisection_family"] else None,
        "elements_per_leaf": c["elements_per_leaf"], "fvm_adequate": c["fvm_adequate"],
        "tessellated_on_the_fly": c["tessellated_on_the_fly"]} for c in configurations.values()),
        key=lambda c: (-c["leaves"], c["code"]))
    total = sum(type_counts.values())
    uniform_counts = uniform["counts"] if uniform else {}
    uniform_total = uniform["elements"] if uniform else 0
    info = dict(uniform["types"]) if uniform else {}
    info.update(types)
    rows = []
    for type_id in sorted(set(type_counts) | set(uniform_counts), key=lambda t: (-type_counts[t], t)):
        entry = info.get(type_id) or type_info(type_id, None, catalogue)
        rows.append({
            "id": type_id, "name": entry["name"], "paper_class": entry["paper_class"], "vtk": entry["vtk"],
            "count": int(type_counts[type_id]), "share": _share(type_counts[type_id], total),
            "uniform_count": int(uniform_counts.get(type_id, 0)) if uniform else None,
            "uniform_share": _share(uniform_counts.get(type_id, 0), uniform_total) if uniform else None,
        })
    final = sum(r["count"] for r in rows if r["paper_class"] in PAPER_FINAL)
    result: dict[str, Any] = {
        "paper_final_share": _share(final, total),
        "leaves_in_bisection_family": int(sum(c["leaves"] for c in frequencies if c["uniform_share"] is not None)),
        "type_frequencies": rows,
        "configuration_frequencies": frequencies,
    }
    if uniform:
        uniform_final = sum(r["uniform_count"] for r in rows if r["paper_class"] in PAPER_FINAL)
        result["uniform"] = {"study": "bisection", "face_points": "octree", "configurations": _BISECTION_CONFIGURATIONS,
                             "elements": int(uniform_total), "paper_final_share": _share(uniform_final, uniform_total)}
    return result


def level_counts(tree: Octree) -> dict[str, int]:
    """Leaves per level of an octree (levels that occur)."""
    counts = np.bincount(tree.levels.astype(np.int64))
    return {str(level): int(n) for level, n in enumerate(counts.tolist()) if n}
