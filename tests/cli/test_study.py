"""``cospherical study``: the JSON it prints and the files it writes."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from commands import cospherical

from cospherical.formats.patterns import load, pattern_name

ROOT = Path(__file__).resolve().parents[2]


def test_study_cli_json_shape(tmp_path):
    result = subprocess.run(
        [sys.executable, "-m", "cospherical", "study", "bisection", "--box", "1", "2", "4", "--format", "json",
         "--out", str(tmp_path), "--compare-paper"],
        capture_output=True, text=True,
    )
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


def test_study_leaves_json_and_tables(tmp_path):
    result = cospherical("study", "leaves", "--box", "1", "2", "4", "--format", "json", "--out", str(tmp_path))
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
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
