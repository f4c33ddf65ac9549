"""The bisection study."""

from __future__ import annotations

import subprocess
import sys


def test_a_bisection_study_loads_no_numpy():
    # numpy takes a tenth of a second to import: the bisection study and its command do without it.
    script = ("import sys; from cospherical.cli import main; main(['study', 'bisection', '--format', 'json']); "
              "sys.exit('numpy' in sys.modules)")
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
