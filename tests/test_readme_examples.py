"""Every shell example of the README runs as written.

Heavy examples run at a small size, in a scratch clone of the repository (the
machinery, shared with the docs site's examples, is ``examples.py``). Lines not run
here, and why: the set-up (it made the environment these tests run in), the test
suite itself, and ``cospherical reproduce``, which
``outputs/test_reproduce.py::test_reproduce_regenerates_committed_files_byte_for_byte`` runs and
compares byte for byte.
"""

from __future__ import annotations

import re
import shutil

import pytest
from examples import ROOT, heavy_lines_without_figures, make_scratch, run_shell_example, shell_examples

README = (ROOT / "README.md").read_text()
NOT_RUN = ("scripts/setup.sh", "cospherical reproduce", "-m pytest")


def test_the_readme_has_its_examples_and_no_real_hosts():
    lines = shell_examples(README)
    # the front door: the two commands, one tessellation, one mesh with its dual (the rest is in docs/,
    # run by tests/test_docs.py)
    assert sum("scripts/setup.sh" in line for line in lines) == 2
    assert any(line.startswith("cospherical tessellate ") for line in lines)
    assert any(line.startswith("cospherical mesh ") and "--dual" in line for line in lines)
    assert not re.search(r"tcp://\d", README), "use a placeholder host such as tcp://SCHEDULER:8786"


def test_heavy_examples_say_their_time_and_size():
    assert heavy_lines_without_figures(README) == []


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    return make_scratch(tmp_path_factory.mktemp("readme") / "repo")


def runnable() -> list[str]:
    return [line for line in shell_examples(README) if not any(skip in line for skip in NOT_RUN)]


@pytest.mark.parametrize("line", runnable())
def test_readme_example_runs(scratch, line):
    run_shell_example(line, scratch)


def test_every_readme_line_is_run_or_explained():
    skipped = [line for line in shell_examples(README) if any(skip in line for skip in NOT_RUN)]
    assert all(shutil.which("bash") for _ in skipped)
    assert len(skipped) <= 3, skipped
