"""A plain ``pip install`` of the wheel works in a fresh virtual environment, away from the checkout.

The fresh environment is made without a pip of its own, and the test's pip installs into it
(``pip --python``): the same resolution of the wheel's dependencies, without ensurepip's
4 CPU-s. ``--no-compile``: pip byte-compiles every installed module otherwise (numpy, scipy,
numba, ...: 15 of the install's 21 CPU-s), which Python does anyway for what it imports.
"""

import json
import os
import subprocess
import sys
import venv
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_wheel_installs_and_runs_in_a_fresh_venv(tmp_path):
    wheels = tmp_path / "wheels"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(wheels), str(ROOT)],
                   check=True, capture_output=True)
    (wheel,) = wheels.glob("cospherical-*.whl")
    # py.typed: the annotations are part of the package, so users' type checkers read them
    assert "cospherical/py.typed" in zipfile.ZipFile(wheel).namelist()
    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=False)
    python = env_dir / "bin" / "python"
    subprocess.run([sys.executable, "-m", "pip", "--python", str(python), "install", "-q", "--no-compile", str(wheel)],
                   check=True, capture_output=True)
    away = tmp_path / "elsewhere"
    away.mkdir()
    # nothing of the checkout on the path (a PYTHONPATH pointing at src/ would shadow the installed package)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    path = subprocess.run([str(python), "-c", "import cospherical.catalogue as c; print(c.catalogue_path())"],
                          cwd=away, env=env, check=True, capture_output=True, text=True).stdout.strip()
    assert "site-packages" in path and Path(path).exists()
    result = subprocess.run([str(env_dir / "bin" / "cospherical"), "tessellate", "--box", "1", "1", "1",
                             "--code", "880000000000"], cwd=away, env=env, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    names = {e["name"] for e in json.loads(result.stdout)["elements"]}
    assert "Deformed Prism (variant 2)" in names  # a name only the shipped catalogue knows
    summary = ROOT / "results" / "bisection-1x2x4.json"
    result = subprocess.run([str(env_dir / "bin" / "cospherical"), "render", "--summary", str(summary),
                             "--out", str(away / "tex")], cwd=away, env=env, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr  # the templates ship in the wheel
    assert "\\begin{longtable}" in (away / "tex" / "elements.tex").read_text()
