"""Names imported where first asked for (``cospherical.lazy.on_first_use``), and the packages that export names so."""

from __future__ import annotations

import math
import subprocess
import sys

import pytest

from cospherical.lazy import on_first_use


def test_a_name_is_imported_when_asked_for_and_kept_under_its_own_name():
    namespace = {"__name__": "example"}
    attribute = on_first_use(namespace, {"sqrt": "math", "root": ("math", "sqrt")})
    assert attribute("root") is math.sqrt and namespace["root"] is math.sqrt and "sqrt" not in namespace
    with pytest.raises(AttributeError, match="^module 'example' has no attribute 'cbrt'$"):
        attribute("cbrt")


def test_the_packages_lazy_names_are_their_modules_objects_loaded_only_when_asked_for():
    # in a fresh interpreter: which modules a name brings in is what the laziness is for
    code = """
import sys
import cospherical, cospherical.mesh.report
lazy = ("cospherical.api.mesh", "cospherical.mesh._dual_device_sections", "cospherical.formats.dual.reader")
before = [name for name in lazy if name in sys.modules]
from cospherical.api.mesh import build_mesh
from cospherical.mesh._dual_device_sections import DualSummary
assert cospherical.build_mesh is build_mesh and cospherical.DualSummary is DualSummary
assert cospherical.mesh.report.DualSummary is DualSummary and cospherical.mesh.report_sections.DualSummary is DualSummary
import cospherical.formats.dual
before += [name for name in lazy[2:] if name in sys.modules]
from cospherical.formats.dual.reader import read_dual
assert cospherical.formats.dual.read_dual is read_dual
print(before)
"""
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "[]"
