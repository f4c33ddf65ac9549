"""Progress bars: drawn on a terminal's stderr, nothing at all where stderr is a file or a pipe."""

from __future__ import annotations

import io
import sys

from cospherical.cli.progress import progress_bar, stage_bars


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_no_terminal_no_bar(capsys, monkeypatch):
    monkeypatch.delitem(sys.modules, "tqdm", raising=False)
    with progress_bar(10, "study") as advance:
        advance(3)
        advance(7)
    assert capsys.readouterr().err == "" and "tqdm" not in sys.modules  # not even imported


def test_a_terminal_sees_the_count_done_of_the_total(monkeypatch):
    terminal = Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    with progress_bar(5, "study") as advance:
        advance(3)
        bar = advance.__self__  # the tqdm bar it advances
        assert (bar.n, bar.total, bar.unit) == (3, 5, "cfg")
    assert "study" in terminal.getvalue() and "0/5" in terminal.getvalue()


def test_stage_bars_open_when_their_stage_starts_and_close_at_the_end(monkeypatch):
    from tqdm import tqdm

    terminal = Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    stages = {"cells": (4, "cells", "chunk"), "table": (None, "table", "entry")}
    with stage_bars(stages) as advance:
        advance("cells", 2)
        assert "0/4" in terminal.getvalue() and "table" not in terminal.getvalue()
        advance("table", 9)
        bars = {bar.desc: (bar.n, bar.total, bar.unit) for bar in tqdm._instances}
        assert bars == {"cells": (2, 4, "chunk"), "table": (9, None, "entry")}
        assert "table" in terminal.getvalue()
    assert not any(bar.desc in stages for bar in tqdm._instances)  # both closed


def test_no_terminal_no_stage_bars(capsys, monkeypatch):
    # a large tree's stages report progress; with stderr not a terminal nothing is drawn and tqdm
    # (which imports multiprocessing and importlib.metadata: ~20 ms of a mesh run) stays unloaded
    monkeypatch.delitem(sys.modules, "tqdm", raising=False)
    with stage_bars({"assembly": (100, "assembling", "leaf")}) as advance:
        advance("assembly", 60)
        advance("assembly", 40)
    assert capsys.readouterr().err == "" and "tqdm" not in sys.modules
