"""The command line as a user runs it: ``python -m cospherical ARGS`` in a real subprocess."""

from __future__ import annotations

import subprocess
import sys


def cospherical(*args, cwd=None, timeout=None, **kwargs) -> subprocess.CompletedProcess:
    """Run ``cospherical ARGS`` (each argument as ``str``); its output is captured as text."""
    return subprocess.run([sys.executable, "-m", "cospherical", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=timeout, **kwargs)


def one_clean_line(result: subprocess.CompletedProcess, needle: str) -> None:
    """The run refused with exit 2 and one line on stderr naming ``needle``, no traceback."""
    assert result.returncode == 2, (result.returncode, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.stderr, result.stderr
    assert needle in lines[0], lines[0]
