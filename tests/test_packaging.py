"""A plain ``pip install`` of the wheel works in a fresh virtual environment, away from the checkout."""

import json
import subprocess
import sys
import venv
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_wheel_installs_and_runs_in_a_fresh_venv(tmp_path):
    wheels = tmp_path / "wheels"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(wheels), str(ROOT)],
                   check=True, capture_output=True)
    (wheel,) = wheels.glob("cospherical-*.whl")
    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=True)
    python = env_dir / "bin" / "python"
    subprocess.run([str(python), "-m", "pip", "install", "-q", str(wheel)], check=True, capture_output=True)
    away = tmp_path / "elsewhere"
    away.mkdir()
    path = subprocess.run([str(python), "-c", "import cospherical.catalogue as c; print(c.catalogue_path())"],
                          cwd=away, check=True, capture_output=True, text=True).stdout.strip()
    assert "site-packages" in path and Path(path).exists()
    result = subprocess.run([str(env_dir / "bin" / "cospherical"), "tessellate", "--box", "1", "1", "1",
                             "--code", "880000000000"], cwd=away, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    names = {e["name"] for e in json.loads(result.stdout)["elements"]}
    assert "Deformed Prism (variant 2)" in names  # a name only the shipped catalogue knows
    summary = ROOT / "results" / "bisection-1x2x4.json"
    result = subprocess.run([str(env_dir / "bin" / "cospherical"), "render", "--summary", str(summary),
                             "--out", str(away / "tex")], cwd=away, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr  # the templates ship in the wheel
    assert "\\begin{longtable}" in (away / "tex" / "elements.tex").read_text()
