"""``cospherical check``: its help names every kind of file it takes, and each kind is checked by what it is."""

from __future__ import annotations

import pytest

from cospherical.cli import main


def test_help_names_every_kind_of_file_check_takes(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    summary = " ".join(capsys.readouterr().out.split())
    assert "check validate catalogues, pattern tables (YAML or SQLite store) and dual.npz files" in summary
    with pytest.raises(SystemExit):
        main(["check", "--help"])
    files = " ".join(capsys.readouterr().out.split())
    files = files[files.index("FILE catalogues"):files.index("options:")]
    for kind in ("catalogues", "pattern tables", "SQLite store", "dual.npz files of mesh --dual"):
        assert kind in files, (kind, files)
