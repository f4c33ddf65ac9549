"""Samples of large sets for the default run; ``pytest --full`` (conftest.py) checks all of them.

A pattern table cut down for the deep check (``cospherical check``), which costs about 1 ms an entry:
the sample keeps every entry that brings a type the entries before it did not (so every type of
the table is checked) and a seeded fraction of the others; a test given ``pytest --full``
(conftest.py) checks the whole table instead.
"""

from __future__ import annotations

import random
import re
from pathlib import Path

FULL = False  # set by conftest.py's pytest_configure from ``--full``


def examples(count: int, share: int = 4) -> int:
    """How many generated inputs a property test draws: ``count`` with ``--full``, else one ``share``-th of it.

    Hypothesis draws fresh inputs on every run (and replays the failures it kept), so each default
    run searches a new part of the space; ``--full`` searches as widely as the counts given."""
    return count if FULL else max(100, count // share)


def sampled_table(path: Path, into: Path, fraction: float, seed: int) -> Path:
    """Write the YAML table ``path`` with only the sampled entries to ``into``; return ``into``."""
    lines = path.read_text().split("\n")
    start = lines.index("configurations:") + 1
    chance, seen, sample = random.Random(seed), set(), []
    for line in lines[start:-1]:
        types = set(re.findall(r'"type": "([^"]+)"', line))
        if not types <= seen or chance.random() < fraction:
            sample.append(line)
            seen |= types
    assert seen and len(sample) < len(lines) - start, "a sample of a table's entries"
    into.write_text("\n".join(lines[:start] + sample + lines[-1:]))
    return into
