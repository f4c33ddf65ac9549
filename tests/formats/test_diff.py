"""What changed between catalogue and pattern-table versions: the report, matched by canonical code.

The command that prints it (exit status, formats, ``--rev``) is tested in tests/cli/test_diff.py."""

from __future__ import annotations

import copy

import pytest

from cospherical import Box
from cospherical.errors import FormatError
from cospherical.files.yamlio import dump_yaml, load_yaml
from cospherical.formats.check import document_data, read_document_file
from cospherical.formats.diff import diff_documents, has_changes, text_report
from cospherical.formats.catalogue_file import build_catalogue, write_catalogue
from cospherical.formats.patterns import write_patterns
from cospherical.studies.engine import bisection_codes, run_study

CODES = bisection_codes()[:96]


@pytest.fixture(scope="module")
def versions(tmp_path_factory):
    """Catalogues and pattern tables of two boxes, plus hand-edited copies."""
    root = tmp_path_factory.mktemp("versions")
    cube = run_study("bisection", Box.parse(("1", "1", "1")), CODES)
    sqrt2 = run_study("bisection", Box.parse(("1", "sqrt(2)", "sqrt(2)")), CODES)
    write_catalogue(build_catalogue([cube]), root / "cube.yaml")
    write_catalogue(build_catalogue([sqrt2]), root / "sqrt2.yaml")
    write_patterns(cube, root / "cube-patterns.yaml", "000000000001")
    write_patterns(sqrt2, root / "sqrt2-patterns.yaml", "000000000002")

    catalogue = load_yaml(root / "cube.yaml")
    edited = copy.deepcopy(catalogue)
    removed = edited["types"].pop(0)
    renamed = edited["types"][0]
    renamed["name"] = "Renamed Element"
    split_type = next(t for t in edited["types"] if t.get("splits"))
    criterion = sorted(split_type["splits"])[0]
    split_type["splits"][criterion] = split_type["splits"][criterion][:-1] or [[{"type": "v4f4-000000", "nodes": [0, 1, 2, 3]}]]
    edited["version"] = "0123456789ab"
    dump_yaml(edited, root / "cube-edited.yaml")

    table = load_yaml(root / "cube-patterns.yaml")
    table_edited = copy.deepcopy(table)
    first = sorted(table_edited["configurations"])[1]
    element = table_edited["configurations"][first]["optimal"][0]
    element["nodes"] = list(reversed(element["nodes"]))
    dropped = sorted(table_edited["configurations"])[2]
    del table_edited["configurations"][dropped]
    dump_yaml(table_edited, root / "cube-patterns-edited.yaml")
    return {"root": root, "removed": removed, "renamed": renamed, "split_type": split_type,
            "criterion": criterion, "first": first, "dropped": dropped}


def diff(old, new) -> tuple[dict, str]:
    """The report of two files, as ``cospherical diff`` reads them, and its text."""
    report = diff_documents(document_data(read_document_file(old)[1]), document_data(read_document_file(new)[1]),
                            str(old), str(new))
    return report, text_report(report, str(old), str(new))


def test_identical_files_have_no_changes(versions):
    for name in ("cube.yaml", "cube-patterns.yaml"):
        path = versions["root"] / name
        report, text = diff(path, path)
        assert not has_changes(report) and text == ""


def test_catalogue_changes(versions):
    root = versions["root"]
    report, text = diff(root / "cube.yaml", root / "cube-edited.yaml")
    assert has_changes(report)
    assert [t["id"] for t in report["removed"]] == [versions["removed"]["id"]]
    assert report["renamed"] == [{"id": versions["renamed"]["id"], "old": report["renamed"][0]["old"],
                                  "new": "Renamed Element"}]
    assert any(s["id"] == versions["split_type"]["id"] and s["criterion"] == versions["criterion"]
               for s in report["splits"])
    assert report["header"]["version"]["new"] == "0123456789ab"
    assert "added" not in report
    assert f"- type {versions['removed']['id']}" in text
    assert f"~ renamed {versions['renamed']['id']}" in text and "Renamed Element" in text
    assert f"~ splits {versions['split_type']['id']}" in text
    assert "header version" in text


def test_catalogues_of_two_boxes(versions):
    root = versions["root"]
    report, _ = diff(root / "cube.yaml", root / "sqrt2.yaml")
    old = {t["code"] for t in load_yaml(root / "cube.yaml")["types"]}
    new = {t["code"] for t in load_yaml(root / "sqrt2.yaml")["types"]}
    assert len(report.get("added", [])) == len(new - old) > 0
    assert len(report.get("removed", [])) == len(old - new)


def test_pattern_changes(versions):
    root = versions["root"]
    report, text = diff(root / "cube-patterns.yaml", root / "cube-patterns-edited.yaml")
    assert report["configurations_removed"] == [versions["dropped"]]
    assert [c["code"] for c in report["changed"]["optimal"]] == [versions["first"]]
    assert report["summary"]["changed_optimal"] == 1
    assert f"- configuration {versions['dropped']}" in text
    assert f"~ {versions['first']} [optimal] (same types, other nodes)" in text


def test_pattern_tables_of_two_boxes_report_the_header_first(versions):
    root = versions["root"]
    _, text = diff(root / "cube-patterns.yaml", root / "sqrt2-patterns.yaml")
    lines = text.splitlines()
    assert lines[2].startswith("header ") and any(line.startswith("header box") for line in lines)
    assert any(line.startswith("~ ") and "[optimal]" in line for line in lines)


def test_a_catalogue_and_a_pattern_table_are_not_compared(versions):
    root = versions["root"]
    with pytest.raises(FormatError, match="cannot compare a catalogue"):
        diff(root / "cube.yaml", root / "cube-patterns.yaml")
