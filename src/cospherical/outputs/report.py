"""Text reports of study summaries, with the paper's figures beside ours."""

from __future__ import annotations

from typing import Any

from ..catalogue import Catalogue, element_options, type_name
from ..paper import comparison_notes, paper_class, paper_comparison, paper_notes, paper_studies, paper_study_key
from ..studies.engine import Study

__all__ = ["comparison_lines", "paper_set_gaps", "study_comparison_lines", "text_report"]


def paper_set_gaps(study: Study, key: str, criterion: str, catalogue: Catalogue | None = None) -> list[dict[str, Any]]:
    """Element types of the study that cannot be split into the paper's kept classes.

    The paper's table for a criterion names the classes it keeps; an element whose
    every split (the element itself included) has a piece outside those classes
    proves that the paper's table cannot come out for this point set.
    """
    kept_classes = set(paper_studies()[key][criterion]["counts"])
    sizes = study.orbit_sizes()
    gaps: dict[str, dict[str, Any]] = {}
    for rep, tess in study.tessellations.items():
        for element in tess.elements:
            options = element_options(tess, element, criterion)
            if any(all((paper_class(p.type) or {}).get("name") in kept_classes for p in o) for o in options):
                continue
            entry = gaps.setdefault(element.type.id, {
                "type": element.type.id, "name": type_name(element.type, catalogue), "configurations": 0,
                "splits": sorted({" + ".join(sorted(type_name(p.type, catalogue) for p in o)) for o in options}),
            })
            entry["configurations"] += sizes[rep]
    return sorted(gaps.values(), key=lambda g: g["type"])


def _mark(paper: object, ours: object) -> str:
    return "" if paper == ours else "  <- differs"


def _region(summary: dict[str, Any]) -> str:
    """Where the FVM test wants the circumcenters: the box, or another base element itself."""
    region: str = summary.get("element", "box")
    return region


def text_report(summary: dict[str, Any], compare_paper: bool = False, study: Study | None = None) -> str:
    """A plain-text report: the frequency table and, if asked, the paper beside it."""
    lines = [
        f"{summary['study']} study{' of the ' + summary['element'] if 'element' in summary else ''}, "
        f"box {' x '.join(summary['box'])}, face points {summary['face_points']}: "
        f"{summary['configurations']} configurations ({summary['orbits']} orbits)",
        f"FVM adequate: {summary['fvm_adequate']} (closed {_region(summary)}), "
        f"{summary['fvm_adequate_open']} (open {_region(summary)})",
    ]
    names = {i: t["name"] for data in summary["criteria"].values() for i, t in data["types"].items()}
    for criterion, data in summary["criteria"].items():
        types = data["types"].values()
        classes = {t["paper_class"] for t in types if t["paper_class"]}
        outside = sum(1 for t in types if not t["paper_class"])
        lines.append("")
        lines.append(f"{criterion}: {data['total']} elements, {data['types_count']} element types "
                     f"({len(classes)} of the paper's classes, {outside} types outside them)")
        # Columns as wide as the longest name: a name is never cut (two rows would read the same).
        width = max([48] + [len(t["name"]) for t in types])
        lines.append(f"  {'id':<14} {'name':<{width}} {'paper class':<32} {'count':>8} {'share':>7} {'configs':>7}")
        for type_id, entry in data["types"].items():
            lines.append(
                f"  {type_id:<14} {entry['name']:<{width}} {(entry['paper_class'] or '-'):<32} "
                f"{entry['count']:>8} {100 * entry['share']:>6.2f}% {entry['configurations']:>7}"
            )
        if data.get("splits"):
            lines.append("  splits used (type -> pieces, configurations):")
            for type_id, used in data["splits"].items():
                for split in used:
                    pieces = " + ".join(names.get(p, p) for p in split["pieces"])
                    lines.append(f"    {names.get(type_id, type_id)} -> {pieces}  ({split['configurations']})")
    if "compared_with" in summary:
        lines.append("")
        lines.extend(study_comparison_lines(summary))
    if compare_paper:
        lines.append("")
        lines.extend(comparison_lines(summary, study))
    return "\n".join(lines) + "\n"


def study_comparison_lines(summary: dict[str, Any]) -> list[str]:
    """The summary's ``compared_with`` study beside it: the figures, then every type's count."""
    other = summary["compared_with"]
    ours, theirs = summary["study"], f"{other['study']} ({other['face_points']})"
    width = max(len(ours), len(theirs), 8)
    names = {i: t["name"] for data in (*summary["criteria"].values(), *other["criteria"].values())
             for i, t in data["types"].items()}
    lines = [f"Beside the {other['study']} study with the {other['face_points']} point policy, same box:",
             f"  {'':<56} {ours:>{width}} {theirs:>{width}}"]

    def row(label: str, mine: object, them: object) -> None:
        lines.append(f"  {label[:56]:<56} {mine:>{width}} {them:>{width}}")

    for key, label in (("configurations", "configurations"), ("orbits", "symmetry orbits"),
                       ("fvm_adequate", "FVM adequate (closed box)"), ("fvm_adequate_open", "FVM adequate (open box)")):
        row(label, summary[key], other[key])
    for criterion, data in summary["criteria"].items():
        them = other["criteria"].get(criterion, {"total": "-", "types_count": "-", "types": {}})
        row(f"{criterion}: elements", data["total"], them["total"])
        row(f"{criterion}: element types", data["types_count"], them["types_count"])
        for type_id in [*data["types"], *(i for i in them["types"] if i not in data["types"])]:
            mine = data["types"].get(type_id, {}).get("count", 0)
            row(f"  {type_id:<14} {names[type_id]}", mine, them["types"].get(type_id, {}).get("count", 0))
    return lines


def comparison_lines(summary: dict[str, Any], study: Study | None = None, catalogue: Catalogue | None = None) -> list[str]:
    """The paper's figures beside ours; with the ``study``, also the elements the paper's kept
    classes cannot tessellate, named by ``catalogue`` (default: the shipped one)."""
    key, _ = paper_study_key(summary)
    if key is None:
        return ["The paper has no study of this box to compare with."]
    lines = [f"Beside the paper ({key}, box {' x '.join(str(x) for x in paper_studies()[key]['box'])}):"]
    for criterion in summary["criteria"]:
        if criterion not in paper_studies()[key]:
            continue
        table = paper_comparison(summary, key, criterion)
        lines.append(f"  {criterion}:")
        width = max([48] + [len(row["class"]) for row in table["rows"]])
        lines.append(f"    {'paper class / type':<{width}} {'paper':>8} {'ours':>8}")
        for row in table["rows"]:
            paper = "-" if row["paper"] is None else row["paper"]
            ours = "-" if row["ours"] is None else row["ours"]
            lines.append(f"    {row['class']:<{width}} {paper:>8} {ours:>8}{_mark(row['paper'], row['ours'])}")
        total = table["total"]
        lines.append(f"    {'total':<{width}} {total['paper']:>8} {total['ours']:>8}{_mark(total['paper'], total['ours'])}")
        classes = table["classes"]
        lines.append(f"    {'element classes':<{width}} {classes['paper']:>8} {classes['ours']:>8}"
                     f"{_mark(classes['paper'], classes['ours'])}")
        if criterion != "optimal" and study is not None:
            gaps = paper_set_gaps(study, key, criterion, catalogue)
            if gaps:
                lines.append("    The paper's kept classes cannot tessellate these elements (every split shown):")
                for gap in gaps:
                    lines.append(f"      {gap['name']} ({gap['configurations']} configurations): "
                                 + "; ".join(gap["splits"]))
    fvm = paper_comparison(summary, key)["fvm_adequate"]
    if fvm["paper"] is not None:  # the paper gives no FVM count for its intersection study
        lines.append(f"  FVM adequate configurations: paper {fvm['paper']}, ours {fvm['closed']} (closed box), "
                     f"{fvm['open']} (open box){_mark(fvm['paper'], fvm['closed'])}")
    lines.append("  Notes:")
    lines.extend(f"  - {paper_notes()[n]}" for n in comparison_notes(summary, key, summary["criteria"]))
    return lines
