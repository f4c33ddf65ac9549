"""Time one in-process ``tessellate`` call against one ``qdelaunay Qz Fv`` run on the same points.

    python benchmarks/bench_tessellate.py [--samples 400]

Both are timed in this one run on the same configurations (random bisection
configurations of the paper's boxes and random 1/16 intersection
configurations of the cube); the figure to compare is the ratio. Writes
results/benchmarks/bench_tessellate.json (benchmarks/record.py).
"""

from __future__ import annotations

import argparse
import random
import shutil
import statistics
import subprocess
import time

from cospherical import Configuration, tessellate
from record import recorded


def qhull(points) -> None:
    text = f"3\n{len(points)}\n" + "\n".join(" ".join(repr(x) for x in p) for p in points.values()) + "\n"
    subprocess.run(["qdelaunay", "Qz", "Fv"], input=text, capture_output=True, text=True, check=True)


def median_ms(function, items) -> float:
    times = []
    for item in items:
        start = time.perf_counter()
        function(item)
        times.append(time.perf_counter() - start)
    return 1000 * statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=400)
    args = parser.parse_args()
    if not shutil.which("qdelaunay"):
        raise SystemExit("qdelaunay not found: install qhull-bin (scripts/setup.sh does)")
    rng = random.Random(1)
    boxes = [("1", "1", "1"), ("1", "2", "4"), ("1", "1.4142", "1.4142"), ("1", "sqrt(2)", "sqrt(2)")]
    sets = {
        "bisection": [
            Configuration.from_code("".join(rng.choice("08") for _ in range(12)), rng.choice(boxes))
            for _ in range(args.samples)
        ],
        "intersection 1/16": [
            Configuration.from_code("".join(rng.choice("0123456789abcdef") for _ in range(12)))
            for _ in range(args.samples)
        ],
    }
    with recorded(__file__) as record:
        print(f"{'configurations':<20} {'tessellate ms':>14} {'qdelaunay ms':>13} {'ratio':>7}")
        for label, configs in sets.items():
            for cfg in configs[:20]:  # warm-up
                tessellate(cfg)
            ours = median_ms(tessellate, configs)
            theirs = median_ms(lambda cfg: qhull(cfg.real_nodes()), configs)
            print(f"{label:<20} {ours:>14.2f} {theirs:>13.2f} {theirs / ours:>6.2f}x")
            record.add(f"one `tessellate` call, {label} configuration, median of {len(configs)}",
                       f"{ours:.2f} ms (one `qdelaunay Qz Fv` run: {theirs:.2f} ms, {theirs / ours:.1f}x)")


if __name__ == "__main__":
    main()
