"""The command line as a user runs it: ``python -m cospherical ARGS`` in a real subprocess."""

from __future__ import annotations

import subprocess
import sys


def cospherical(*args, cwd=None, timeout=None, **kwargs) -> subprocess.CompletedProcess:
    """Run ``cospherical ARGS`` (each argument as ``str``); its output is captured as text."""
    return subprocess.run([sys.executable, "-m", "cospherical", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=timeout, **kwargs)
