"""Study summaries: the JSON shape of ``cospherical study``, shared by every study family.

A summary holds, per criterion, the frequency table of the element types
(count, share, configurations using the type, V/E/F, name and paper class), the
total, the number of types and of paper classes, and the splits used.  The
bisection study counts with Python objects and the intersection study with
numpy arrays; both hand their counts to :func:`frequency_table`, so the shape
is made in one place.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from typing import Any, Mapping

from ..catalogue import type_name
from ..core.element_types import ElementType
from ..paper import paper_class
from .engine import Study

__all__ = ["TypeInfo", "compared_with", "frequency_table", "study_summary"]


@dataclass(frozen=True)
class TypeInfo:
    """An element type as a summary describes it."""

    name: str
    paper_class: str | None
    vertices: int
    edges: int
    faces: int

    @classmethod
    def of(cls, etype: ElementType, name: str | None = None) -> TypeInfo:
        """The description of a type; ``name`` overrides the catalogue's name."""
        return cls(name or type_name(etype), (paper_class(etype) or {}).get("name"),
                   etype.vertices, etype.edges, etype.faces)


def frequency_table(counts: Mapping[str, int], configurations: Mapping[str, int], types: Mapping[str, TypeInfo],
                    splits: Mapping[str, Mapping[tuple[str, ...], int]]) -> dict[str, Any]:
    """One criterion's part of a summary.

    Parameters
    ----------
    counts, configurations : mapping of type id to int
        Elements of the type over the whole study, and configurations holding at least one.
    types : mapping of type id to TypeInfo
        The description of every type in ``counts``.
    splits : mapping of type id to {pieces: count}
        For each type that is split, how many elements were split into each
        sorted tuple of piece types.

    Returns
    -------
    dict
        ``total``, ``types_count``, ``paper_classes_count``, ``types`` (by
        decreasing count, then id) and, when there are splits, ``splits``.
    """
    total = sum(counts.values())
    rows = {}
    for type_id in sorted(counts, key=lambda i: (-counts[i], i)):
        info = types[type_id]
        rows[type_id] = {"name": info.name, "paper_class": info.paper_class, "count": counts[type_id],
                         "share": round(counts[type_id] / total, 6), "configurations": configurations[type_id],
                         "vertices": info.vertices, "edges": info.edges, "faces": info.faces}
    data = {"total": total, "types_count": len(rows),
            "paper_classes_count": len({r["paper_class"] or k for k, r in rows.items()}), "types": rows}
    if splits:
        data["splits"] = {type_id: [{"pieces": list(pieces), "configurations": n} for pieces, n in sorted(used.items())]
                          for type_id, used in sorted(splits.items())}
    return data


def study_summary(study: Study, names: Mapping[str, tuple[str, list[str]]] | None = None) -> dict[str, Any]:
    """The study's statistics in the JSON shape of ``cospherical study --format json``.

    ``names``: type id -> (name, aliases), as :func:`cospherical.catalogue.type_names`
    gives them, to use instead of the shipped catalogue's names (while the
    catalogue itself is being rebuilt; the aliases are the paper classes).
    """
    criteria = {}
    for criterion in study.criteria:
        counts, configurations, types = {}, {}, {}
        for entry in study.type_counts(criterion):
            t = entry.type
            counts[t.id], configurations[t.id] = entry.count, entry.configurations
            types[t.id] = TypeInfo.of(t, names[t.id][0] if names and t.id in names else None)
        splits: dict[str, Counter[tuple[str, ...]]] = {}
        for type_id, used in study.choices[criterion].splits.items():
            for split, n in used.items():
                splits.setdefault(type_id, Counter())[tuple(sorted(piece_type for piece_type, _ in split))] += n
        criteria[criterion] = frequency_table(counts, configurations, types, splits)
    return {
        "study": study.name,
        **({"element": study.element} if study.element != "cuboid" else {}),
        "box": list(study.box.texts),
        "face_points": study.face_points,
        "configurations": study.configurations,
        "orbits": study.orbits,
        "fvm_adequate": study.fvm_adequate,
        "fvm_adequate_open": study.fvm_adequate_open,
        "criteria": criteria,
    }


def compared_with(summary: dict[str, Any], other: dict[str, Any]) -> dict[str, Any]:
    """``summary`` with an entry ``compared_with``: another study's figures, to set beside ours.

    The other study's configurations, orbits, FVM counts and, per criterion, its
    total, number of types and per-type counts (with names); the leaf study is
    compared so with the octree-policy bisection study of the same box.

    Examples
    --------
    >>> ours = {"study": "leaves", "configurations": 2, "criteria": {}}
    >>> other = {"study": "bisection", "face_points": "octree", "configurations": 1, "orbits": 1,
    ...          "fvm_adequate": 1, "fvm_adequate_open": 0,
    ...          "criteria": {"optimal": {"total": 4, "types_count": 1,
    ...                                   "types": {"v4f4-8f0284": {"name": "tetrahedron", "count": 4}}}}}
    >>> compared_with(ours, other)["compared_with"]["criteria"]["optimal"]["types"]
    {'v4f4-8f0284': {'name': 'tetrahedron', 'count': 4}}
    """
    keys = ("study", "face_points", "configurations", "orbits", "fvm_adequate", "fvm_adequate_open")
    criteria = {
        criterion: {"total": data["total"], "types_count": data["types_count"],
                    "types": {i: {"name": t["name"], "count": t["count"]} for i, t in data["types"].items()}}
        for criterion, data in other["criteria"].items()
    }
    return {**summary, "compared_with": {**{key: other[key] for key in keys}, "criteria": criteria}}
