"""A pattern table cut down for the deep check (``cospherical check``), which costs about 1 ms an entry.

The sample keeps every entry that brings a type the entries before it did not (so every type of
the table is checked) and a seeded fraction of the others; a test given ``pytest --full``
(conftest.py) checks the whole table instead.
"""

from __future__ import annotations

import random
import re
from pathlib import Path


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
