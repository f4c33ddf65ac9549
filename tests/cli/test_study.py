"""``cospherical study``: each family's own help, the JSON it prints and the files it writes."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from commands import in_process

from cospherical.formats.patterns import load, pattern_name

ROOT = Path(__file__).resolve().parents[2]


def test_study_cli_json_shape(tmp_path, capsys):
    # in this process (the study as a process, interrupted, is test_reliability.py's)
    result = in_process(capsys, "study", "bisection", "--box", "1", "2", "4", "--format", "json",
                        "--out", tmp_path, "--compare-paper")
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    assert data["study"] == "bisection" and data["box"] == ["1", "2", "4"] and data["configurations"] == 4096
    assert data["face_points"] == "octree"
    optimal = data["criteria"]["optimal"]
    assert optimal["total"] == 45581 == sum(t["count"] for t in optimal["types"].values())
    assert data["fvm_adequate"] >= data["fvm_adequate_open"]
    assert data["paper"]["fvm_adequate"]["paper"] == 132
    stem = pattern_name("bisection", ("1", "2", "4"))
    assert json.loads((tmp_path / f"{stem}.json").read_text())["criteria"] == data["criteria"]
    assert len(load(tmp_path / f"{stem}.yaml").configurations) == 4096


def test_study_leaves_json_and_tables(tmp_path, capsys):
    from cospherical.cli import main

    # in this process (the study is the cost, not the start-up a process would add)
    assert main(["study", "leaves", "--box", "1", "2", "4", "--format", "json", "--out", str(tmp_path)]) == 0
    data = json.loads(capsys.readouterr().out)
    assert (data["study"], data["face_points"], data["configurations"], data["orbits"]) == \
        ("leaves", "explicit", 6210, 1012)
    assert (data["fvm_adequate"], data["fvm_adequate_open"]) == (1720, 268)
    assert {c: data["criteria"][c]["total"] for c in data["criteria"]} == \
        {"optimal": 74901, "internal_faces": 74901, "internal_edges_and_faces": 75077}
    optimal = data["criteria"]["optimal"]
    assert optimal["total"] == sum(t["count"] for t in optimal["types"].values())
    other = data["compared_with"]
    assert (other["study"], other["face_points"], other["configurations"]) == ("bisection", "octree", 4096)
    assert other["criteria"]["optimal"]["total"] == 45581
    assert json.loads((tmp_path / "leaves-1x2x4.json").read_text()) == data
    committed = ROOT / "patterns" / "leaves-1x2x4.yaml"
    assert (tmp_path / "leaves-1x2x4.yaml").read_bytes() == committed.read_bytes()


def test_each_study_family_has_its_own_help(capsys):
    from cospherical.cli import main

    texts = {}
    for family in ("bisection", "leaves", "intersection"):
        with pytest.raises(SystemExit) as exit:
            main(["study", family, "--help"])
        assert exit.value.code == 0
        texts[family] = capsys.readouterr().out
    assert len(set(texts.values())) == 3
    assert "--resume" in texts["intersection"] and "--resume" not in texts["bisection"]
    assert "--element" in texts["bisection"] and "--element" not in texts["leaves"]
    assert "--face-points" not in texts["leaves"] and "--box" not in texts["intersection"]
    assert main(["study", "bisection", "--resume"]) == 2  # hidden, still refused by name
    assert "option of the intersection study only" in capsys.readouterr().err


def test_study_cli_element(tmp_path, capsys):
    import json

    result = in_process(capsys, "study", "bisection", "--element", "tetrahedron", "--format", "json", "--out", tmp_path)
    data = json.loads(result.stdout)
    assert data["element"] == "tetrahedron" and data["configurations"] == 64
    optimal = data["criteria"]["optimal"]
    assert optimal["total"] == sum(t["count"] for t in optimal["types"].values())
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bisection-tetrahedron-1x1x1.json",
                                                          "bisection-tetrahedron-1x1x1.yaml"]
    assert in_process(capsys, "check", tmp_path / "bisection-tetrahedron-1x1x1.yaml").returncode == 0
    result = in_process(capsys, "study", "leaves", "--element", "prism")
    assert result.returncode == 2 and len(result.stderr.strip().splitlines()) == 1
