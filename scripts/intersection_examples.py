"""Write src/cospherical/data/intersection-examples.yaml: one example of every element type of the
intersection studies (R = 4, 8, 16, every insertion order, every criterion), for the catalogue.

    python scripts/intersection_examples.py [--jobs 2]

The nine studies take about 15 minutes on the shared two-core machine; ``cospherical reproduce`` then
rebuilds each type from its example (a configuration code and node ids: the cube, octree
points) in well under a second, so the catalogue holds every type of the intersection
studies without the main job running them.  Each line: the type id, the example, the
studies it appears in and, per split criterion, the piece types of the splits the study
used for it.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from cospherical.files.flowyaml import sequence_line
from cospherical.files.yamlio import atomic_write
from cospherical.choices import INSERTION_ORDERS
from cospherical.studies.intersection.run import example_elements, run_intersection

TARGET = Path(__file__).resolve().parents[1] / "src" / "cospherical" / "data" / "intersection-examples.yaml"
RESOLUTIONS = (4, 8, 16)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    args = parser.parse_args()
    raw: dict = {}
    studies: dict[str, list[str]] = {}
    splits: dict[str, dict[str, list]] = {}
    for resolution in RESOLUTIONS:
        for order in INSERTION_ORDERS:
            start = time.perf_counter()
            label = f"intersection 1/{resolution} {order}"
            found: dict = {}
            summary = run_intersection(resolution, order, jobs=args.jobs, examples=found)
            for type_id, example in found.items():
                raw.setdefault(type_id, example)
            for criterion, data in summary["criteria"].items():
                suffix = "" if criterion == "optimal" else f" ({criterion})"
                for type_id in data["types"]:
                    studies.setdefault(type_id, []).append(label + suffix)
                for type_id, used in data.get("splits", {}).items():
                    known = splits.setdefault(type_id, {}).setdefault(criterion, [])
                    for split in used:
                        if split["pieces"] not in known:
                            known.append(split["pieces"])
            print(f"{label}: {len(found)} types, {time.perf_counter() - start:.0f} s", file=sys.stderr)
    examples = example_elements(raw)
    lines = ["# One example of every element type of the intersection studies (R = 4, 8, 16, every insertion\n",
             "# order and criterion): written by scripts/intersection_examples.py, read by cospherical reproduce.\n",
             "types:\n"]
    for type_id in sorted(t for t in examples if t in studies):  # met in a study (not only as an unused option)
        code, nodes = examples[type_id]
        lines.append(sequence_line({
            "type": type_id, "configuration": code, "nodes": list(nodes), "studies": studies.get(type_id, []),
            "splits": {c: sorted(pieces) for c, pieces in sorted(splits.get(type_id, {}).items())},
        }))
    atomic_write(TARGET, "".join(lines))
    print(f"wrote {TARGET} ({len(examples)} types)", file=sys.stderr)


if __name__ == "__main__":
    main()
