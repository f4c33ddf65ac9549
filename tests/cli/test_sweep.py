"""``cospherical sweep``: a grid of boxes as JSON beside direct studies, its figures compiled; usage errors in one line."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from commands import in_process

from cospherical.studies.sweep import box_statistics


@pytest.mark.oracle_pdflatex
def test_sweep_cli_json_and_figures(tmp_path):
    result = subprocess.run([sys.executable, "-m", "cospherical", "sweep", "--ratios", "1:2:2", "2:2:1",
                             "--format", "json", "--out", str(tmp_path), "--jobs", "2"], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    assert [b["box"] for b in data["boxes"]] == [["1", "1", "2"], ["1", "2", "2"]]
    for entry in data["boxes"]:
        direct = box_statistics(tuple(entry["box"]))
        assert {k: entry[k] for k in ("fvm_adequate", "types", "total")} == \
               {k: direct[k] for k in ("fvm_adequate", "types", "total")}
    assert (tmp_path / "heatmap.png").read_bytes()[:4] == b"\x89PNG"
    assert subprocess.run(["pdflatex", "-interaction=nonstopmode", "-halt-on-error", "figures.tex"],
                          cwd=tmp_path, capture_output=True).returncode == 0


@pytest.mark.parametrize("args, needle", [
    (["--ratios", "1:2", "1:2:2"], "MIN:MAX:STEPS"),
    (["--ratios", "2:1:3", "1:2:2"], "MIN <= MAX"),
    (["--ratios", "1:x:3", "1:2:2"], "b range"),
    (["--ray", "1,2,r"], "each 1 or r"),
    (["--ray", "1,r,r", "--range", "0:2"], "R_MIN"),
])
def test_sweep_usage_errors(capsys, args, needle):
    result = in_process(capsys, "sweep", *args)  # the command's code here: a process added 0.4 CPU-s of start-up
    assert result.returncode == 2 and needle in result.stderr and len(result.stderr.strip().splitlines()) == 1
