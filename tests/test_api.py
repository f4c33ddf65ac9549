"""The public API: every module says what it makes public, and what the docs name exists."""

from __future__ import annotations

import ast
import importlib
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"
# A dotted path beginning with the package: a module, or a name in one (cospherical.core.exact.Length).
DOTTED = re.compile(r"\bcospherical(?:\.[A-Za-z_]\w*)+")


def _modules() -> list[tuple[str, Path]]:
    found = []
    for path in sorted(SRC.rglob("*.py")):
        parts = path.relative_to(SRC).with_suffix("").parts
        found.append((".".join(parts[:-1] if parts[-1] == "__init__" else parts), path))
    return found


def _declares_all(tree: ast.Module) -> bool:
    for node in tree.body:
        targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(node, ast.AnnAssign) else []
        if any(isinstance(t, ast.Name) and t.id == "__all__" for t in targets):
            return True
    return False


def _resolve(path: str):
    """The object a dotted path names (the longest importable module, then attributes), or None."""
    parts = path.split(".")
    for i in range(len(parts), 0, -1):
        try:
            target = importlib.import_module(".".join(parts[:i]))
        except ModuleNotFoundError:
            continue
        for attribute in parts[i:]:
            if not hasattr(target, attribute):
                return None
            target = getattr(target, attribute)
        return target
    return None


def test_every_module_declares_what_it_makes_public():
    missing = [name for name, path in _modules() if not _declares_all(ast.parse(path.read_text()))]
    assert not missing, f"modules without __all__: {missing}"


def test_every_public_name_exists_and_is_not_marked_private():
    for name, _ in _modules():
        if name == "cospherical.__main__":  # importing it runs the command
            continue
        module = importlib.import_module(name)
        for public in module.__all__:
            assert hasattr(module, public), f"{name}.__all__ names {public!r}, which it does not define"
            assert not public.startswith("_") or public == "__version__", f"{name}.__all__: {public!r} is private"


def test_every_module_path_in_docstrings_and_docs_exists():
    # A docstring or page naming a module that was renamed or removed sends the reader nowhere.
    files = [*SRC.rglob("*.py"), *(ROOT / "docs").rglob("*.md"), ROOT / "README.md", ROOT / "CONTRIBUTING.md"]
    broken = []
    for file in files:
        text = file.read_text()
        for match in DOTTED.finditer(text):
            if _resolve(match.group(0)) is None:
                broken.append(f"{file.relative_to(ROOT)}:{text.count(chr(10), 0, match.start()) + 1}: {match.group(0)}")
    assert not broken, "\n".join(broken)


def test_the_api_reference_shows_public_names_only():
    page = (ROOT / "docs" / "reference" / "api.md").read_text()
    for path in re.findall(r"^::: (\S+)", page, re.M):
        target = _resolve(path)
        assert target is not None, path
        module_name, _, name = path.rpartition(".")
        if isinstance(target, type(ast)):  # a whole module
            continue
        assert name in importlib.import_module(module_name).__all__, f"{path}: documented, but not in __all__"


def test_a_broken_path_is_found():
    # The check above can fail: a renamed module's old path does not resolve.
    assert _resolve("cospherical.studies.engine.run_study") is not None
    assert _resolve("cospherical.studies.bisection.run_study") is None
    assert _resolve("cospherical.formats.store") is None


def test_a_type_checker_sees_every_lazy_name_where_it_loads():
    # cospherical/__init__.py loads the names of _API on first use (__getattr__); its
    # `if TYPE_CHECKING:` imports show a user's checker the same names from the same modules
    import cospherical

    tree = ast.parse((SRC / "cospherical" / "__init__.py").read_text())
    block = next(node for node in tree.body if isinstance(node, ast.If) and ast.unparse(node.test) == "TYPE_CHECKING")
    seen = {alias.asname or alias.name: ("cospherical" + "." * (node.level - 1) + "." + node.module, alias.name)
            for node in block.body if isinstance(node, ast.ImportFrom) for alias in node.names}
    # a name given under another (load_patterns = _patterns.load), its module imported as _patterns
    modules = {name: ".".join(seen.pop(name)) for name in [name for name in seen if name.startswith("_")]}
    seen.update({node.targets[0].id: (modules[node.value.value.id], node.value.attr)
                 for node in block.body if isinstance(node, ast.Assign)})
    lazy = {name: where if isinstance(where, tuple) else (where, name) for name, where in cospherical._API.items()}
    assert seen == lazy
