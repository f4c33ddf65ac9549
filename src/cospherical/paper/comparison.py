"""Our study summaries beside the paper's published figures, and the notes on why they differ.

Everything here works on a study summary (the JSON shape of ``cospherical
study``), so the text report and the LaTeX tables compare in one way.
"""

from __future__ import annotations

from fractions import Fraction
from typing import Any, Iterable

from ..core.configuration import Box
from .published import paper_classes, paper_studies

__all__ = ["comparison_notes", "paper_comparison", "paper_study_key"]


def _normalised(box: Box) -> tuple[Fraction, ...]:
    squared = sorted(box.squared)
    return tuple(s / squared[0] for s in squared)


def paper_study_key(summary: dict[str, Any]) -> tuple[str | None, list[str]]:
    """The paper's study to compare a study summary with, and the notes on why figures may differ.

    The paper computed its sqrt 2 case at 1.4142; a box at exactly sqrt 2 is
    compared with it too, marked as a different box.

    Examples
    --------
    >>> paper_study_key({"study": "bisection", "box": ["2", "2", "2"], "face_points": "octree"})
    ('bisection_A', ['classes'])
    """
    if summary["study"] == "intersection":
        return "intersection_cube", ["classes", "insertion_order"]
    if summary["study"] != "bisection" or summary.get("element", "cuboid") != "cuboid":
        return None, []  # the paper studied cuboids only
    notes = ["classes"]
    if summary["face_points"] != "octree":
        notes.append("none_policy")
    ratios = _normalised(Box.parse(summary["box"]))
    for key, entry in paper_studies().items():
        if not key.startswith("bisection"):
            continue
        lengths = [str(x) for x in entry["box"]]
        as_computed = Box.parse(["1.4142" if "sqrt" in x else x for x in lengths])
        if ratios == _normalised(as_computed):
            return key, notes
        if ratios == _normalised(Box.parse(lengths)):
            return key, notes + ["exact_sqrt2"]
    return None, notes


def paper_comparison(summary: dict[str, Any], key: str, criterion: str = "optimal") -> dict[str, Any]:
    """Rows (paper class or type name, paper count, our count) for one criterion."""
    paper = paper_studies()[key]
    published = paper.get(criterion, {})
    ours: dict[str, int] = {}
    for entry in summary["criteria"][criterion]["types"].values():
        label = entry["paper_class"] or entry["name"]
        ours[label] = ours.get(label, 0) + entry["count"]
    order = [c["name"] for c in paper_classes()]
    labels = [n for n in order if n in published.get("counts", {}) or n in ours]
    labels += sorted(n for n in ours if n not in labels)
    rows = [
        {"class": n, "paper": published.get("counts", {}).get(n), "ours": ours.get(n)}
        for n in labels
    ]
    return {
        "paper_study": key,
        "criterion": criterion,
        "rows": rows,
        "total": {"paper": published.get("total"), "ours": summary["criteria"][criterion]["total"]},
        "classes": {"paper": len(published.get("counts", {})) or None, "ours": len(ours)},
        "fvm_adequate": {
            "paper": paper.get("fvm_adequate_configurations"),
            "closed": summary["fvm_adequate"],
            "open": summary["fvm_adequate_open"],
        },
    }


def comparison_notes(summary: dict[str, Any], key: str, criteria: Iterable[str]) -> list[str]:
    """The keys of :func:`~cospherical.paper.paper_notes` that explain a comparison of these criteria.

    The study's own notes (:func:`paper_study_key`), ``splits`` when a split
    criterion is compared, and ``fvm`` when the optimal comparison shows an FVM
    count the paper publishes and neither of ours reproduces.
    """
    criteria = list(criteria)
    notes = paper_study_key(summary)[1]
    if any(c != "optimal" and c in paper_studies()[key] for c in criteria):
        notes.append("splits")
    fvm = paper_comparison(summary, key)["fvm_adequate"]
    if "optimal" in criteria and fvm["paper"] is not None and fvm["paper"] not in (fvm["closed"], fvm["open"]):
        notes.append("fvm")
    return notes
