"""The command line as a user runs it: ``python -m cospherical ARGS`` in a real subprocess, or its code in this one.

A process costs about 0.4 CPU-s of start-up (the imports) for a refusal that takes milliseconds: a test that
checks what a command says runs ``cospherical.cli.main`` here (``in_process``), and a few run the real
process, as a user meets it (exit status, stderr, the console entry point).
"""

from __future__ import annotations

import subprocess
import sys
from types import SimpleNamespace


def cospherical(*args, cwd=None, timeout=None, **kwargs) -> subprocess.CompletedProcess:
    """Run ``cospherical ARGS`` (each argument as ``str``); its output is captured as text."""
    return subprocess.run([sys.executable, "-m", "cospherical", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=timeout, **kwargs)


def in_process(capsys, *args) -> SimpleNamespace:
    """``cospherical ARGS`` through ``cospherical.cli.main`` in this process: its exit status, stdout and stderr
    (``capsys``, pytest's capture), as ``one_clean_line`` reads a process's."""
    from cospherical.cli import main

    returncode = main([str(a) for a in args])
    captured = capsys.readouterr()
    return SimpleNamespace(returncode=returncode, stdout=captured.out, stderr=captured.err)


def one_clean_line(result: subprocess.CompletedProcess | SimpleNamespace, needle: str) -> None:
    """The run refused with exit 2 and one line on stderr naming ``needle``, no traceback."""
    assert result.returncode == 2, (result.returncode, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.stderr, result.stderr
    assert needle in lines[0], lines[0]
