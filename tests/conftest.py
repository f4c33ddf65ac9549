import sys
from pathlib import Path

import pytest

# The shared test helpers (oracle.py, strategies.py, commands.py, examples.py) live here, above the
# test folders (tests/<package>/, one per package of src/cospherical): imported as top-level modules.
sys.path.insert(0, str(Path(__file__).parent))


@pytest.fixture(scope="session")
def paper_studies():
    """The paper's three bisection studies (boxes A, B, C; every criterion), made once per test
    process: the paper's tables and the split checks of several modules read them, none changes them."""
    from cospherical import Box
    from cospherical.studies.engine import bisection_codes, run_study

    boxes = {"A": ("1", "1", "1"), "B": ("1", "2", "4"), "C": ("1", "1.4142", "1.4142")}
    return {key: run_study("bisection", Box.parse(box), bisection_codes()) for key, box in boxes.items()}
