"""The type checker passes: mypy, configured in pyproject.toml ([tool.mypy]), strict where it says.

mypy reads the annotations the way a user's checker does (the package ships ``py.typed``): the
strict modules (CONTRIBUTING.md lists them) checked with the flags of ``--strict``, the rest of the
package with mypy's default checks, every public function annotated everywhere.  Each run starts from an empty cache, as in a fresh CI
clone (about 11 CPU-s for the whole package: pyproject.toml says which libraries mypy does not
follow, and why).
"""

import ast
import os
import re
import subprocess
import sys
from pathlib import Path

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10: mypy's own dependency reads TOML
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]
CONFIG = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["mypy"]


def mypy(*arguments: str, cwd: Path, cache: Path) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "MYPYPATH")}
    return subprocess.run([sys.executable, "-m", "mypy", "--config-file", str(ROOT / "pyproject.toml"),
                           "--cache-dir", str(cache), *arguments], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=300)


def test_the_package_passes_the_type_checker(tmp_path):
    # run as a developer runs it, a bare `mypy` in the checkout: the configuration names the target
    result = mypy(cwd=ROOT, cache=tmp_path / "cache")
    assert result.returncode == 0, result.stdout + result.stderr
    assert result.stdout.splitlines()[-1].startswith("Success: no issues found"), result.stdout


def _strict_modules() -> list[str]:
    return [module for override in CONFIG["overrides"] if override.get("disallow_untyped_defs")
            for module in ([override["module"]] if isinstance(override["module"], str) else override["module"])]


def test_the_strict_sections_turn_on_every_flag_of_strict():
    # A per-module section cannot say `strict`: it lists the flags, and must list all that
    # --strict turns on (those that are per-module; the global ones are in [tool.mypy]).
    text = subprocess.run([sys.executable, "-m", "mypy", "--help"], capture_output=True, text=True,
                          check=True).stdout
    listed = re.search(r"--strict\s+Strict mode; enables the following flags:(.*?)(?:\n  -|\Z)", text, re.S)
    assert listed is not None
    flags = {flag.replace("-", "_") for flag in re.findall(r"--([a-z-]+)", re.sub(r"-\s*\n\s*", "-", listed[1]))}
    assert "disallow_untyped_defs" in flags and len(flags) >= 10
    strict = next(override for override in CONFIG["overrides"] if override.get("disallow_untyped_defs"))
    per_module = {flag for flag in flags if flag not in ("warn_redundant_casts", "warn_unused_configs")}
    assert per_module <= {key for key, value in strict.items() if value is True}
    assert all(CONFIG.get(flag) is True for flag in flags - per_module)
    assert "cospherical.*" in _strict_modules()


def test_strict_modules_refuse_an_unannotated_function(tmp_path):
    # The checker really is strict where the configuration says so, and only there: the same
    # unannotated function is an error in a module of the package and accepted in a script beside it.
    for package in ("cospherical", "cospherical/core"):
        (tmp_path / package).mkdir()
        (tmp_path / package / "__init__.py").write_text("")
    probe = "def half(x):\n    return x / 2\n"
    (tmp_path / "cospherical" / "core" / "probe.py").write_text(probe)
    (tmp_path / "script.py").write_text(probe)
    result = mypy("cospherical/core/probe.py", "script.py", cwd=tmp_path, cache=tmp_path / "cache")
    assert result.returncode == 1
    errors = [line for line in result.stdout.splitlines() if ": error:" in line]
    assert len(errors) == 1 and errors[0].startswith("cospherical/core/probe.py:1:"), result.stdout
    assert "[no-untyped-def]" in errors[0]


def _unannotated(source: str) -> list[str]:
    """The public functions of ``source`` (nested ones and methods too) missing an annotation: of a
    parameter (``self`` and ``cls`` aside, ``*args`` and ``**kwargs`` included) or of the return."""
    missing = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and not node.name.startswith("_"):
            arguments = node.args
            parameters = [*arguments.posonlyargs, *arguments.args, *arguments.kwonlyargs,
                          *filter(None, (arguments.vararg, arguments.kwarg))]
            if node.returns is None or any(p.annotation is None for p in parameters if p.arg not in ("self", "cls")):
                missing.append(f"{node.name} (line {node.lineno})")
    return missing


def test_the_count_of_unannotated_functions_sees_what_is_missing():
    probe = ("def a(x: int) -> int: ...\ndef b(x) -> int: ...\ndef c(x: int): ...\ndef d(*xs) -> None: ...\n"
             "def e(**kw) -> None: ...\ndef _f(x): ...\nclass K:\n    def m(self, y: int) -> None:\n"
             "        def inner(z): ...\n    def n(self): ...\n")
    assert [name.split()[0] for name in _unannotated(probe)] == ["b", "c", "d", "e", "n", "inner"]


def test_every_public_function_is_annotated():
    # strict modules are held to it by mypy; this holds the rest of the package too (mypy's default checks
    # skip an unannotated function's body, so one left unannotated is a function nobody type-checks)
    package = ROOT / "src" / "cospherical"
    missing = {str(path.relative_to(package)): found for path in sorted(package.rglob("*.py"))
               if (found := _unannotated(path.read_text()))}
    assert missing == {}


def test_contributing_lists_the_strict_modules_of_the_configuration():
    # CONTRIBUTING.md tells a contributor where mypy is strict: the same list as pyproject.toml, in its order
    text = (ROOT / "CONTRIBUTING.md").read_text()
    listed = re.search(r"<!-- strict modules -->(.*?)<!-- /strict modules -->", text, re.S)
    assert listed is not None, "CONTRIBUTING.md's list of strict modules, between its markers"
    assert re.findall(r"`([^`]+)`", listed[1]) == _strict_modules()
