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

from ..caches import cached
from ..catalogue import Catalogue
from ..core.configuration import Box, Configuration
from ..files.data import data_path
from .assembly import PAPER_FINAL, Mesh, type_info
from .tree import Octree

__all__ = ["in_bisection_family", "level_counts", "mesh_statistics", "occurrences", "shipped_uniform", "statistics",
           "uniform_figures", "uniform_study"]

_BISECTION_CONFIGURATIONS = 4096


def uniform_study(box: Box, catalogue: Catalogue, computed: bool = False) -> dict[str, Any]:
    """Element counts per type of the uniform-weight bisection study of ``box`` (octree policy, optimal),
    the types named by ``catalogue``.

    The study is a pure function of the box's proportions (every type id, count and
    VTK cell is unchanged when the box is scaled).  It costs 0.2 s for a cube and
    0.5-0.8 s for the other shapes of the shipped pattern tables, more than a
    small mesh: those shapes' figures ship precomputed in ``data/uniform-studies.json``
    (:func:`shipped_uniform`, written by ``scripts/uniform_studies.py`` from
    :func:`uniform_figures`; the tests compute them again and compare), and any
    other box is computed here.  ``computed=True`` computes it whatever the box
    (``mesh --check all``).
    """
    figures = None if computed else shipped_uniform(box)
    if figures is None:
        figures = uniform_figures(box)
    info = {type_id: type_info(type_id, None, catalogue) if type_id in catalogue else dict(own)
            for type_id, own in figures["types"].items()}
    return {"counts": dict(figures["counts"]), "types": info, "elements": figures["elements"]}


def uniform_figures(box: Box) -> dict[str, Any]:
    """The uniform bisection study of ``box`` as data no catalogue names: ``box`` (its texts), ``counts`` and
    ``types`` (each type's own name, paper class, VTK cell, vertices and faces) per type id, ``elements``."""
    from ..catalogue import Catalogue
    from ..studies.engine import bisection_codes, run_study

    study = run_study("bisection", box, bisection_codes(), "octree", criteria=("optimal",))
    nobody = Catalogue.empty(1)
    return {"box": list(box.texts), "counts": {tc.type.id: tc.count for tc in study.type_counts("optimal")},
            "types": {tc.type.id: type_info(tc.type.id, tc.type, nobody) for tc in study.type_counts("optimal")},
            "elements": study.total("optimal")}


def shipped_uniform(box: Box) -> dict[str, Any] | None:
    """The shipped :func:`uniform_figures` of a box shaped like ``box`` (the same proportions), else ``None``."""
    ours = box.squared
    for figures in _shipped_uniform_studies():
        theirs = Box.parse(figures["box"]).squared
        if all(theirs[a] * ours[0] == ours[a] * theirs[0] for a in range(3)):
            return figures
    return None


@cached(maxsize=1)
def _shipped_uniform_studies() -> list[dict[str, Any]]:
    """``data/uniform-studies.json``'s studies (package data, as trusted as the code that reads it)."""
    import json

    studies: list[dict[str, Any]] = json.loads(data_path("uniform-studies.json").read_text(encoding="utf-8"))["studies"]
    return studies


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
