"""Write src/cospherical/data/uniform-studies.json: the uniform bisection study of each shape of box the
shipped pattern tables are made for, so that ``cospherical mesh`` of such a box reads its report's
``uniform`` figures instead of running the study (0.2 s for a cube, 0.5-0.8 s for the others).

    python scripts/uniform_studies.py

Each study: the box's texts, the element count per type id, each type's own name, paper class,
VTK cell, vertices and faces (the catalogue's names are added when a report is made), and the
total of elements (:func:`cospherical.mesh.statistics.uniform_figures`).  A domain of the same
proportions (2 x 2 x 2 for 1 x 1 x 1) uses the same figures.  tests/mesh/test_statistics.py
computes them again and compares.
"""

from __future__ import annotations

import json
from pathlib import Path

from cospherical.core.configuration import Box
from cospherical.files.yamlio import atomic_write
from cospherical.mesh.statistics import uniform_figures

TARGET = Path(__file__).resolve().parents[1] / "src" / "cospherical" / "data" / "uniform-studies.json"
# The boxes of patterns/*.yaml (the cuboid tables), in that order.
BOXES = (("1", "1", "1"), ("1", "2", "4"), ("1", "1.4142", "1.4142"), ("1", "sqrt(2)", "sqrt(2)"))


def uniform_studies_text() -> str:
    """The file's text (deterministic)."""
    studies = [{"box": list(Box.parse(list(box)).texts), **uniform_figures(Box.parse(list(box))).to_dict()}
               for box in BOXES]
    return json.dumps({"comment": "the uniform bisection study (octree points, optimal) of each box: written by "
                       "scripts/uniform_studies.py, read by cospherical.mesh.statistics.uniform_study",
                       "studies": studies}, indent=1) + "\n"


if __name__ == "__main__":
    atomic_write(TARGET, uniform_studies_text())
    print(f"wrote {TARGET}")
