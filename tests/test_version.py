"""The version in one place: the package, the command and the wheel's metadata say the same."""

from __future__ import annotations

import re
from pathlib import Path

import cospherical
from cospherical.cli import main
from cospherical.version import __version__


def test_the_command_and_the_package_say_the_version(capsys):
    assert re.fullmatch(r"\d+\.\d+\.\d+", __version__) and cospherical.__version__ == __version__
    try:
        main(["--version"])
    except SystemExit as stop:
        assert stop.code in (0, None)
    assert __version__ in capsys.readouterr().out
    pyproject = (Path(__file__).resolve().parents[1] / "pyproject.toml").read_text()
    assert 'path = "src/cospherical/version.py"' in pyproject  # hatch reads the wheel's version from it
