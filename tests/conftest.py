import os
import sys
from collections.abc import Mapping
from pathlib import Path

import pytest

# One BLAS thread per process: the suite runs on as many workers as cores (-n 2 on 2), and OpenBLAS's
# threads spin while they wait, burning CPU the workers need (DEVSIM's diode: 15 CPU-s with numpy's
# default threads at load 5, 5 with one). Set before numpy is first imported, here and in every command
# the tests start (they inherit it); a value the user set stays.
for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

# The shared test helpers (oracle.py, strategies.py, commands.py, examples.py) live here, above the
# test folders (tests/<package>/, one per package of src/cospherical): imported as top-level modules.
sys.path.insert(0, str(Path(__file__).parent))


def pytest_addoption(parser):
    parser.addoption("--full", action="store_true",
                     help="heavy oracles check every case, not the seeded sample the default run checks")


def pytest_configure(config):
    """Tell the helpers whether ``--full`` was given before the test modules are imported: a module's
    hypothesis settings (test_fuzz.py's counts) are fixed when it is imported, before any fixture runs."""
    import sampling

    sampling.FULL = bool(config.getoption("--full", False))


def pytest_sessionstart(session):
    """Under xdist, compile the numba kernels once, into their on-disk cache, before the workers start.

    In a fresh clone every process that reaches a kernel before its cache is written compiles
    it again (about 6 CPU-s each; 8.5 before the walk's helpers lost their literal-typed second
    compile and the walk numba's sort): both workers, a study's pool workers, the commands the tests
    start (measured on a fresh clone: 8 intersection tests on 2 workers, 35.7 CPU-s with this, 44.8
    without). Run in the controller only, as a command of its own: the kernels alone, on the arguments the
    intersection study hands them (the orbit keys of R = 2, one configuration's cells), which compiles the
    same signatures as the whole R = 2 study (the same cache files) for 5.0 CPU-s instead of 5.8; with a warm
    cache it costs the cache's reading, about 0.7 CPU-s. Its failure is the tests' to report."""
    if hasattr(session.config, "workerinput") or not getattr(session.config.option, "numprocesses", None):
        return
    import subprocess

    subprocess.run([sys.executable, "-c", "import numpy as np; "
                    "from cospherical.studies.intersection.family import orbits; "
                    "from cospherical.studies.intersection.run import tessellate_chunk; "
                    "orbits(2); tessellate_chunk(np.array([0], dtype=np.int64))"], capture_output=True)


@pytest.fixture(scope="session")
def full(request) -> bool:
    """Whether ``--full`` was given: a test that checks a seeded sample of a large set checks all of it."""
    return request.config.getoption("--full")


class _Studies(Mapping):
    """The bisection study of each box, with every criterion, made when first read: a worker that
    runs only the tests of one box makes only its study."""

    def __init__(self, boxes: dict):
        self._boxes, self._made = boxes, {}

    def __getitem__(self, key):
        if key not in self._made:
            from cospherical import Box
            from cospherical.studies.engine import bisection_codes, run_study

            self._made[key] = run_study("bisection", Box.parse(self._boxes[key]), bisection_codes())
        return self._made[key]

    def __iter__(self):
        return iter(self._boxes)

    def __len__(self):
        return len(self._boxes)


@pytest.fixture(scope="session")
def paper_studies():
    """The paper's three bisection studies (boxes A, B, C; every criterion), each made once per test
    process: the paper's tables, the split checks of several modules and the intersection study at
    resolution 2 read them, none changes them."""
    return _Studies({"A": ("1", "1", "1"), "B": ("1", "2", "4"), "C": ("1", "1.4142", "1.4142")})
