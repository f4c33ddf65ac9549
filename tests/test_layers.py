"""The layers hold: import-linter's contracts pass, and a wrong import breaks them; ruff's rules pass."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LINT = Path(sys.executable).with_name("lint-imports")
RUFF = Path(sys.executable).with_name("ruff")


def lint(source: Path, cwd: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(source)}
    return subprocess.run([str(LINT), "--config", str(ROOT / "pyproject.toml"), "--no-cache"], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=120)


def test_contracts_are_kept():
    result = lint(ROOT / "src", ROOT)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "0 broken" in result.stdout


# One wrong import per contract: the module (under src/cospherical), the line appended to it, and what
# import-linter says of it.
WRONG_IMPORTS = [
    # The core reaching up into the catalogue is exactly the circle the layers forbid.
    ("core/geometry.py", "from ..catalogue import type_name", "cospherical.core.geometry -> cospherical.catalogue"),
    # One command importing another breaks "one module per subcommand".
    ("cli/check.py", "from . import diff", "cospherical.cli.check -> cospherical.cli.diff"),
    # Inside the core: a configuration needs no Delaunay cells; reaching up to them inverts the data flow.
    ("core/configuration.py", "from .delaunay import delaunay_cells",
     "cospherical.core.configuration -> cospherical.core.delaunay"),
    # A writer reaching into the studies: formats only reads and writes what is computed below it.
    ("formats/diff.py", "from ..studies.engine import run_study", "cospherical.formats.diff -> cospherical.studies.engine"),
    # The intersection study's statistics importing its run: the circle its layers broke.
    ("studies/intersection/statistics.py", "from .run import run_intersection",
     "cospherical.studies.intersection.statistics is not allowed to import"),
    # One element's pieces know nothing of the mesh's sums built on them.
    ("mesh/dual/pieces.py", "from .sums import mesh_dual", "cospherical.mesh.dual.pieces -> cospherical.mesh.dual.sums"),
    # The tree's arrays know nothing of the refinement that fills them.
    ("mesh/tree.py", "from .octree import build_octree", "cospherical.mesh.tree -> cospherical.mesh.octree"),
    # A cluster's cells know nothing of the step that asks for them (they were split out of it).
    ("mesh/merged_cells.py", "from .delaunay import retessellate",
     "cospherical.mesh.merged_cells -> cospherical.mesh.delaunay"),
    # The zip writer knows no file format of ours: the dual's writer builds on it, not the other way.
    ("formats/deflated.py", "from .dual import write_dual", "cospherical.formats.deflated -> cospherical.formats.dual"),
    # One check reaching into another: the mesh's checks stand side by side.
    ("mesh/checks/volume.py", "from .conformity import pair_faces",
     "cospherical.mesh.checks.volume -> cospherical.mesh.checks.conformity"),
    # dual.npz's member table knows nothing of the writer that writes it.
    ("formats/dual/members.py", "from .writer import write_dual",
     "cospherical.formats.dual.members -> cospherical.formats.dual.writer"),
]


def test_wrong_imports_break_the_contracts(tmp_path):
    shutil.copytree(ROOT / "src" / "cospherical", tmp_path / "cospherical",
                    ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc"))
    for module, wrong, _ in WRONG_IMPORTS:
        target = tmp_path / "cospherical" / module
        target.write_text(target.read_text() + f"\n{wrong}  # wrong on purpose\n")
    result = lint(tmp_path, tmp_path)
    assert result.returncode != 0
    assert "Contracts: 0 kept, 11 broken." in result.stdout
    for _, _, reported in WRONG_IMPORTS:
        assert reported in result.stdout, reported


def test_ruff_finds_nothing():
    # The rules of [tool.ruff.lint]: undefined and unused names, syntax, ambiguous names.
    result = subprocess.run([str(RUFF), "check", "--no-cache", "src", "tests"], cwd=ROOT, capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 0, result.stdout + result.stderr


def test_ruff_reports_an_undefined_name(tmp_path):
    # The rules are really on: a name used before any definition is reported, by file and rule.
    (tmp_path / "wrong.py").write_text("def f():\n    return undefined_on_purpose\n")
    result = subprocess.run([str(RUFF), "check", "--no-cache", "--output-format", "concise", "--config",
                             str(ROOT / "pyproject.toml"), "wrong.py"],
                            cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert result.returncode == 1
    assert "wrong.py:2:12: F821" in result.stdout


def test_every_cache_is_bounded_and_declared_in_one_place():
    # cospherical.caches.cached is the one way to memoise: a bare functools cache elsewhere
    # would grow without bound in a long process and be missing from caches()/clear_caches().
    import re

    import pytest

    from cospherical.caches import cached

    bare = re.compile(r"\blru_cache\b|\bfunctools\.cache\b|^@cache\b", re.M)
    offenders = [str(path.relative_to(ROOT)) for path in sorted((ROOT / "src").rglob("*.py"))
                 if path.name != "caches.py" and bare.search(path.read_text())]
    assert offenders == []
    for size in (None, 0, True):
        with pytest.raises(ValueError, match="bounded"):
            cached(size)




def unmirrored(src: Path, tests: Path) -> set[str]:
    """The public modules under ``src`` (no leading underscore, packages' ``__init__`` aside) without their
    test module: ``tests/<package>/test_<module>.py`` for ``<package>/<module>.py``."""
    return {str(module.relative_to(src)) for module in src.rglob("*.py")
            if not module.name.startswith("_")
            and not tests.joinpath(*module.relative_to(src).parent.parts, f"test_{module.name}").exists()}


def test_every_public_module_has_its_test_module(tmp_path):
    # CONTRIBUTING: tests/<package>/test_<module>.py tests src/cospherical/<package>/<module>.py.
    missing = unmirrored(ROOT / "src" / "cospherical", ROOT / "tests")
    assert not missing, f"modules without tests/<package>/test_<module>.py: {sorted(missing)}"
    # The check can fail: a module without its test module is found, one with it is not.
    for name in ("src/a/b.py", "src/a/_private.py", "src/a/__init__.py", "src/c.py", "tests/test_c.py"):
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).touch()
    assert unmirrored(tmp_path / "src", tmp_path / "tests") == {"a/b.py"}
