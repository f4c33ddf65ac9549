"""``cospherical study``: the JSON it prints and the files it writes."""

from __future__ import annotations

import json
import subprocess
import sys

from cospherical.formats.patterns import load, pattern_name


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
