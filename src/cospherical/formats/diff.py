"""What changed between two catalogue versions, or two pattern-table versions.

Element types are matched by canonical code, never by name, so a renamed type
is reported as renamed, not as one removed and one added.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable
from typing import Any

from ..errors import FormatError, one_line
from .patterns import Entries, entry_elements

__all__ = ["diff_catalogues", "diff_documents", "diff_patterns", "document_kind", "text_report"]


def document_kind(data: object, name: str) -> str:
    """``catalogue`` or ``patterns``, from the document's own keys."""
    if isinstance(data, dict) and "types" in data and "configurations" not in data:
        return "catalogue"
    if isinstance(data, dict) and "configurations" in data and "types" not in data:
        return "patterns"
    raise FormatError(f"{name}: neither a catalogue (no 'types') nor a pattern table (no 'configurations')")


def _changed(old: dict[str, Any], new: dict[str, Any], keys: Iterable[str]) -> dict[str, Any]:
    return {k: {"old": old.get(k), "new": new.get(k)} for k in keys if old.get(k) != new.get(k)}


def diff_catalogues(old: dict[str, Any], new: dict[str, Any]) -> dict[str, Any]:
    header = _changed(old, new, ("schema_version", "version"))
    old_types = {t["code"]: t for t in old["types"]}
    new_types = {t["code"]: t for t in new["types"]}
    added = [_brief(new_types[c]) for c in sorted(set(new_types) - set(old_types), key=lambda c: new_types[c]["id"])]
    removed = [_brief(old_types[c]) for c in sorted(set(old_types) - set(new_types), key=lambda c: old_types[c]["id"])]
    renamed, aliases, splits, fields = [], [], [], []
    for code in sorted(set(old_types) & set(new_types), key=lambda c: new_types[c]["id"]):
        a, b = old_types[code], new_types[code]
        if a["name"] != b["name"]:
            renamed.append({"id": b["id"], "old": a["name"], "new": b["name"]})
        # every other field of the type: faces, V/E/F, VTK type, chirality, example, studies, ...
        other = sorted(k for k in set(a) | set(b) if k not in _REPORTED_APART and a.get(k) != b.get(k))
        if other:
            fields.append({"id": b["id"], "name": b["name"], "fields": other})
        if a.get("aliases", []) != b.get("aliases", []):
            aliases.append({"id": b["id"], "name": b["name"], "old": a.get("aliases", []), "new": b.get("aliases", [])})
        for criterion in sorted(set(a.get("splits", {})) | set(b.get("splits", {}))):
            before, after = a.get("splits", {}).get(criterion, []), b.get("splits", {}).get(criterion, [])
            if before != after:
                splits.append({"id": b["id"], "name": b["name"], "criterion": criterion,
                               "old": [_split_text(s) for s in before], "new": [_split_text(s) for s in after]})
    kept = []
    old_criteria, new_criteria = old.get("criteria", {}), new.get("criteria", {})
    for criterion in sorted(set(old_criteria) | set(new_criteria)):
        before = set(old_criteria.get(criterion, {}).get("kept", []))
        after = set(new_criteria.get(criterion, {}).get("kept", []))
        if before != after:
            kept.append({"criterion": criterion, "now_kept": sorted(after - before), "no_longer_kept": sorted(before - after)})
    changes = {"header": header, "added": added, "removed": removed, "renamed": renamed,
               "changed": fields, "aliases": aliases, "splits": splits, "kept": kept}
    return {"kind": "catalogue", **{k: v for k, v in changes.items() if v}}


# Fields of a type with a report of their own; the canonical code is what matches types.
_REPORTED_APART = {"code", "name", "aliases", "splits"}


def _brief(entry: dict[str, Any]) -> dict[str, Any]:
    return {"id": entry["id"], "name": entry["name"], "vef": [entry["vertices"], entry["edges"], entry["faces"]]}


def _split_text(split: Iterable[dict[str, Any]]) -> str:
    return " + ".join(f"{piece['type']}{piece['nodes']}" for piece in split)


def _types(elements: Iterable[dict[str, Any]] | None) -> list[str]:
    counts = Counter(e["type"] for e in elements or [])
    return [f"{n} x {t}" if n > 1 else t for t, n in sorted(counts.items())]


def _what_changed(before: list[dict[str, Any]] | None, after: list[dict[str, Any]] | None) -> str:
    """``types``, ``nodes`` (same types) or ``circumcenters`` (same types and nodes); no elements as none."""
    before, after = before or [], after or []
    if Counter(e["type"] for e in before) != Counter(e["type"] for e in after):
        return "types"
    if [(e["type"], e["nodes"]) for e in before] != [(e["type"], e["nodes"]) for e in after]:
        return "nodes"
    return "circumcenters"


def diff_patterns(old: dict[str, Any], new: dict[str, Any]) -> dict[str, Any]:
    header = _changed(old, new, [k for k in {**old, **new} if k != "configurations"])  # every header field
    old_conf, new_conf = old["configurations"], new["configurations"]
    added = sorted(set(new_conf) - set(old_conf))
    removed = sorted(set(old_conf) - set(new_conf))
    criteria = [c for c in new.get("criteria", []) if c in old.get("criteria", [])]
    changed: dict[str, list[Any]] = {}
    fvm = []
    # Entries written alike are alike: tables of a million entries that mostly agree
    # (the YAML and the store of one table) are compared without decoding those.
    as_written = isinstance(old_conf, Entries) and isinstance(new_conf, Entries)
    for code in sorted(set(old_conf) & set(new_conf)):
        if as_written and old_conf.text(code) == new_conf.text(code):
            continue
        a, b = old_conf[code], new_conf[code]
        if a.get("fvm_adequate") != b.get("fvm_adequate"):
            fvm.append({"code": code, "old": a.get("fvm_adequate"), "new": b.get("fvm_adequate")})
        for criterion in criteria:
            before, after = entry_elements(a, criterion), entry_elements(b, criterion)
            if before != after:
                changed.setdefault(criterion, []).append(
                    {"code": code, "old": _types(before), "new": _types(after), "what": _what_changed(before, after)}
                )
    summary = {"configurations_added": len(added), "configurations_removed": len(removed),
               "fvm_changed": len(fvm), **{f"changed_{c}": len(v) for c, v in changed.items()}}
    result = {"kind": "patterns", "header": header,
              "summary": {k: v for k, v in summary.items() if v},
              "configurations_added": added, "configurations_removed": removed,
              "fvm_adequate": fvm, "changed": changed}
    return {k: v for k, v in result.items() if v or k == "kind"}


def diff_documents(old: dict[str, Any], new: dict[str, Any], old_name: str, new_name: str) -> dict[str, Any]:
    kinds = document_kind(old, old_name), document_kind(new, new_name)
    if kinds[0] != kinds[1]:
        label = {"catalogue": "a catalogue", "patterns": "a pattern table"}
        raise FormatError(f"cannot compare {label[kinds[0]]} ({old_name}) with {label[kinds[1]]} ({new_name})")
    return diff_catalogues(old, new) if kinds[0] == "catalogue" else diff_patterns(old, new)


def has_changes(report: dict[str, Any]) -> bool:
    return any(k != "kind" for k in report)


def text_report(report: dict[str, Any], old_name: str, new_name: str) -> str:
    """Human-readable diff; empty when nothing changed.  Each line as a terminal shows it as written
    (:func:`~cospherical.errors.one_line`): the file names and the names from the files are data, and a
    newline or an ESC sequence in one must neither forge a line nor drive the terminal."""
    if not has_changes(report):
        return ""
    lines = [f"--- {old_name}", f"+++ {new_name}"]
    for key, change in report.get("header", {}).items():
        lines.append(f"header {key}: {change['old']!r} -> {change['new']!r}")
    if report["kind"] == "catalogue":
        for sign, key in (("+", "added"), ("-", "removed")):
            for entry in report.get(key, []):
                lines.append(f"{sign} type {entry['id']} {entry['name']} (V/E/F {'/'.join(map(str, entry['vef']))})")
        for entry in report.get("renamed", []):
            lines.append(f"~ renamed {entry['id']}: {entry['old']!r} -> {entry['new']!r}")
        for entry in report.get("changed", []):
            lines.append(f"~ changed {entry['id']} {entry['name']}: {', '.join(entry['fields'])}")
        for entry in report.get("aliases", []):
            lines.append(f"~ aliases {entry['id']} {entry['name']}: {entry['old']} -> {entry['new']}")
        for entry in report.get("splits", []):
            lines.append(f"~ splits {entry['id']} {entry['name']} [{entry['criterion']}]:")
            lines.extend(f"    - {s}" for s in entry["old"] if s not in entry["new"])
            lines.extend(f"    + {s}" for s in entry["new"] if s not in entry["old"])
        for entry in report.get("kept", []):
            lines.append(f"~ kept [{entry['criterion']}]: now kept {entry['now_kept']}, no longer kept {entry['no_longer_kept']}")
    else:
        summary = report.get("summary", {})
        if summary:
            lines.append("summary: " + ", ".join(f"{k.replace('_', ' ')} {v}" for k, v in summary.items()))
        lines.extend(f"+ configuration {code}" for code in report.get("configurations_added", []))
        lines.extend(f"- configuration {code}" for code in report.get("configurations_removed", []))
        for entry in report.get("fvm_adequate", []):
            lines.append(f"~ {entry['code']} fvm_adequate: {entry['old']} -> {entry['new']}")
        for criterion, entries in report.get("changed", {}).items():
            for entry in entries:
                note = {"types": "", "nodes": " (same types, other nodes)",
                        "circumcenters": " (same elements, other circumcenters)"}[entry["what"]]
                lines.append(f"~ {entry['code']} [{criterion}]{note}: {', '.join(entry['old'])} -> {', '.join(entry['new'])}")
    return "".join(one_line(line) + "\n" for line in lines)
