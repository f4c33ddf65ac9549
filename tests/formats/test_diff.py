"""``cospherical diff`` on real catalogue and pattern-table versions, through the CLI."""

from __future__ import annotations

import copy
import json
import subprocess

import pytest
import yaml
from commands import cospherical

from cospherical import Box
from cospherical.files.yamlio import dump_yaml, load_yaml
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


def test_identical_files_give_exit_0_and_no_output(versions):
    for name in ("cube.yaml", "cube-patterns.yaml"):
        path = str(versions["root"] / name)
        result = cospherical("diff", path, path)
        assert (result.returncode, result.stdout, result.stderr) == (0, "", "")


@pytest.mark.oracle_pyyaml
@pytest.mark.parametrize("fmt", ["text", "json", "yaml"])
def test_catalogue_changes_in_every_format(versions, fmt):
    root = versions["root"]
    result = cospherical("diff", str(root / "cube.yaml"), str(root / "cube-edited.yaml"), "--format", fmt)
    assert result.returncode == 1, result.stderr
    if fmt == "text":
        out = result.stdout
        assert f"- type {versions['removed']['id']}" in out
        assert f"~ renamed {versions['renamed']['id']}" in out and "Renamed Element" in out
        assert f"~ splits {versions['split_type']['id']}" in out
        assert "header version" in out
        return
    report = json.loads(result.stdout) if fmt == "json" else yaml.safe_load(result.stdout)
    assert [t["id"] for t in report["removed"]] == [versions["removed"]["id"]]
    assert report["renamed"] == [{"id": versions["renamed"]["id"], "old": report["renamed"][0]["old"],
                                  "new": "Renamed Element"}]
    assert any(s["id"] == versions["split_type"]["id"] and s["criterion"] == versions["criterion"]
               for s in report["splits"])
    assert report["header"]["version"]["new"] == "0123456789ab"
    assert "added" not in report


def test_catalogues_of_two_boxes(versions):
    root = versions["root"]
    result = cospherical("diff", str(root / "cube.yaml"), str(root / "sqrt2.yaml"), "--format", "json")
    assert result.returncode == 1
    report = json.loads(result.stdout)
    old = {t["code"] for t in load_yaml(root / "cube.yaml")["types"]}
    new = {t["code"] for t in load_yaml(root / "sqrt2.yaml")["types"]}
    assert len(report.get("added", [])) == len(new - old) > 0
    assert len(report.get("removed", [])) == len(old - new)


@pytest.mark.oracle_pyyaml
@pytest.mark.parametrize("fmt", ["text", "json", "yaml"])
def test_pattern_changes_in_every_format(versions, fmt):
    root = versions["root"]
    result = cospherical("diff", str(root / "cube-patterns.yaml"), str(root / "cube-patterns-edited.yaml"),
                         "--format", fmt)
    assert result.returncode == 1, result.stderr
    if fmt == "text":
        assert f"- configuration {versions['dropped']}" in result.stdout
        assert f"~ {versions['first']} [optimal] (same types, other nodes)" in result.stdout
        return
    report = json.loads(result.stdout) if fmt == "json" else yaml.safe_load(result.stdout)
    assert report["configurations_removed"] == [versions["dropped"]]
    assert [c["code"] for c in report["changed"]["optimal"]] == [versions["first"]]
    assert report["summary"]["changed_optimal"] == 1


def test_pattern_tables_of_two_boxes_report_the_header_first(versions):
    root = versions["root"]
    result = cospherical("diff", str(root / "cube-patterns.yaml"), str(root / "sqrt2-patterns.yaml"))
    assert result.returncode == 1
    lines = result.stdout.splitlines()
    assert lines[2].startswith("header ") and any(line.startswith("header box") for line in lines)
    assert any(line.startswith("~ ") and "[optimal]" in line for line in lines)


def test_mixing_kinds_and_bad_files_exit_2(versions, tmp_path):
    root = versions["root"]
    result = cospherical("diff", str(root / "cube.yaml"), str(root / "cube-patterns.yaml"))
    assert result.returncode == 2 and "cannot compare a catalogue" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    (tmp_path / "junk.yaml").write_text("a: [1, 2\n")
    result = cospherical("diff", str(root / "cube.yaml"), str(tmp_path / "junk.yaml"))
    assert result.returncode == 2 and "junk.yaml" in result.stderr and "Traceback" not in result.stderr
    result = cospherical("diff", str(root / "cube.yaml"))
    assert result.returncode == 2


def test_rev_reads_the_old_version_from_git(versions, tmp_path):
    repo = tmp_path / "repo"
    repo.mkdir()
    git = ["git", "-c", "user.name=t", "-c", "user.email=t@example.invalid"]
    subprocess.run(git + ["init", "-q"], cwd=repo, check=True)
    target = repo / "catalogue.yaml"
    target.write_bytes((versions["root"] / "cube.yaml").read_bytes())
    subprocess.run(git + ["add", "."], cwd=repo, check=True)
    subprocess.run(git + ["commit", "-qm", "v1"], cwd=repo, check=True)
    assert cospherical("diff", "--rev", "HEAD", "catalogue.yaml", cwd=repo).returncode == 0
    target.write_bytes((versions["root"] / "cube-edited.yaml").read_bytes())
    result = cospherical("diff", "--rev", "HEAD", "catalogue.yaml", cwd=repo)
    assert result.returncode == 1 and "Renamed Element" in result.stdout
    assert "catalogue.yaml@HEAD" in result.stdout.splitlines()[0]
    result = cospherical("diff", "--rev", "nosuchrev", "catalogue.yaml", cwd=repo)
    assert result.returncode == 2 and len(result.stderr.strip().splitlines()) == 1
