"""``cospherical reproduce``: its folder argument, a progress bar of every configuration, the library's line printed.

What it writes is tested in tests/outputs/test_reproduce.py (the whole run, byte for byte against the committed files).
"""

from __future__ import annotations

import io
import sys
from pathlib import Path

import cospherical.cli.reproduce as command
from cospherical.cli import main
from cospherical.studies.reproduce import paper_studies_total


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_the_library_runs_under_a_bar_of_every_configuration_and_its_line_is_printed(monkeypatch, capsys, tmp_path):
    calls = []

    def reproduce(root, progress):  # the library function, recorded: it runs 30 CPU-s (tests/outputs)
        calls.append(root)
        progress(5)
        return f"wrote {root}/catalogue\nforged: ok\x1b[2J"

    monkeypatch.setattr(command, "reproduce", reproduce)
    terminal = Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    assert main(["reproduce", "--root", str(tmp_path / "a\nb")]) == 0
    assert calls == [tmp_path / "a\nb"]
    assert f"reproduce:   0%|          | 0/{paper_studies_total()}" in terminal.getvalue()
    out = capsys.readouterr().out
    assert out.count("\n") == 1 and "\x1b" not in out and out.endswith("\\nforged: ok\\x1b[2J\n")
    monkeypatch.chdir(tmp_path)
    assert main(["reproduce"]) == 0 and calls[-1] == Path(".")  # the default: where the command runs


def test_an_empty_root_is_refused_before_anything_runs(monkeypatch, capsys):
    monkeypatch.setattr(command, "reproduce", lambda root, progress: (_ for _ in ()).throw(AssertionError("ran")))
    assert main(["reproduce", "--root", ""]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "an empty path" in err
