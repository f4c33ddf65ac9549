"""Running the examples of a Markdown document as written: one helper for the README and the docs site.

Shell examples are the lines of its ```sh blocks (comments stripped); heavy ones run at a
small size, only their size arguments rewritten (``SMALLER``). They run in a scratch clone
of the repository, so outputs such as ``results/sweep`` never touch the checkout, with the
few stand-in files the examples name as the reader's own (``OLD.yaml``, ``NEW.yaml``,
``SRC``). Python examples are its ```python blocks.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# size arguments of heavy examples -> a small size
SMALLER = [
    (re.compile(r"--resolution \d+"), "--resolution 2"),
    (re.compile(r"^(cospherical study intersection)(?!.*--resolution)"), r"\1 --resolution 2"),
    (re.compile(r"^(python benchmarks/bench_intersection.py)"), r"\1 --resolution 2 --sample 3"),
    (re.compile(r"^(python benchmarks/bench_tessellate.py)"), r"\1 --samples 5"),
    (re.compile(r"^(python benchmarks/bench_mesh.py)"), r"\1 --levels 4"),
    (re.compile(r"^(python benchmarks/bench_regions.py)"), r"\1 --levels 4"),
    (re.compile(r"^(python benchmarks/bench_scale.py)"), r"\1 --levels 3"),  # L 10 is two processes of minutes and GBs
    (re.compile(r"^(python benchmarks/bench_outputs.py)"), r"\1 --levels 3"),
    (re.compile(r"^(python benchmarks/bench_startup.py)"), r"\1 --runs 1 --every 64 --tables 'bisection-tetra*'"),
    (re.compile(r"^(python benchmarks/bench_bisection.py)"), r"\1 --every 64"),
    (re.compile(r"^(cospherical sweep --ratios \S+):\d+ (\S+):\d+"), r"\1:2 \2:2"),  # 2 x 2 grid values
    # formats/test_patterns.py and core/test_shapes.py check the bisection and shape tables deeply in-process: the
    # example checks the others, the leaf tables
    (re.compile(r"^(cospherical check catalogue/catalogue.yaml) patterns/\*\.yaml"), r"\1 patterns/leaves-*.yaml"),
    (re.compile(r"^(cospherical mesh .*)--levels \d+"), r"\1--levels 3"),
    (re.compile(r"^(python examples/poisson.py).*"), r"\1 --uniform 2 3 --graded 4"),
    (re.compile(r"^(python benchmarks/bench_dual.py --poisson).*"), r"\1 --uniform 2 --graded 4"),
    (re.compile(r"^(python benchmarks/bench_dual.py)(?! --poisson)"), r"\1 --levels 4"),
]


def shell_examples(text: str) -> list[str]:
    """The command lines of a document's ```sh blocks, comments stripped."""
    lines = []
    for block in re.findall(r"```sh\n(.*?)```", text, re.S):
        for line in block.splitlines():
            command = re.sub(r"\s+#.*$", "", line).strip()
            if command and not command.startswith("#"):
                lines.append(command)
    return lines


def python_examples(text: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def heavy_lines_without_figures(text: str) -> list[str]:
    """Heavy example lines that do not say their run time (and, with --patterns, their size) beside them."""
    missing = []
    for block in re.findall(r"```sh\n(.*?)```", text, re.S):
        lines = block.splitlines()
        for i, line in enumerate(lines):
            heavy = re.search(r"study intersection|reproduce|sweep|--pdf|pytest|check |benchmarks/", line)
            if not heavy or line.lstrip().startswith("#"):
                continue
            said = line + (lines[i - 1] if i and lines[i - 1].lstrip().startswith("#") else "")
            if not re.search(r"\d+(\.\d+)? ?(s|min|minutes?|seconds?)\b", said):
                missing.append(f"no run time beside: {line}")
            elif "--patterns" in line and not re.search(r"\d+(\.\d+)? ?[MG]B", said):
                missing.append(f"no size beside: {line}")
    return missing


def make_scratch(folder: Path) -> Path:
    """A clone of the committed repository with the stand-ins for the reader's own files."""
    subprocess.run(["git", "clone", "-q", str(ROOT), str(folder)], check=True)
    catalogue = (folder / "catalogue" / "catalogue.yaml").read_text()
    (folder / "OLD.yaml").write_text(catalogue)
    (folder / "NEW.yaml").write_text(catalogue.replace('"name": "Tetrahedron"', '"name": "simplex"', 1))
    (folder / "SRC").symlink_to(folder / "src")  # "an older src/": this one
    return folder


def run_shell_example(line: str, cwd: Path) -> None:
    """Run one example line as a reader would (the venv's commands first on PATH) and check its outcome."""
    command = line
    for pattern, replacement in SMALLER:
        command = pattern.sub(replacement, command)
    bin_dir = str(Path(sys.executable).parent)
    env = {**os.environ, "PATH": bin_dir + os.pathsep + os.environ["PATH"]}
    result = subprocess.run(["bash", "-c", command], cwd=cwd, env=env, capture_output=True, text=True,
                            timeout=1800)  # a guard against hangs only: a loaded machine is slow
    if "SCHEDULER" in command:  # a placeholder host: one line, exit 2
        assert result.returncode == 2 and len(result.stderr.strip().splitlines()) == 1, result.stderr
        return
    expected = (0, 1) if " diff " in f" {command} " else (0,)
    assert result.returncode in expected, (command, result.stderr[-2000:])
    assert "Traceback" not in result.stderr


def run_python_example(snippet: str, cwd: Path, name: str) -> str:
    """Run one Python example in ``cwd``; what it printed (an example shows its result)."""
    printed = io.StringIO()
    with _chdir(cwd), contextlib.redirect_stdout(printed):
        exec(compile(snippet, name, "exec"), {"__name__": "__example__"})
    return printed.getvalue()


@contextlib.contextmanager
def _chdir(path: Path):
    before = os.getcwd()
    os.chdir(path)
    try:
        yield
    finally:
        os.chdir(before)
