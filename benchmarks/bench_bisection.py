"""The cube's bisection study against two baselines, all timed in this one run.

    python benchmarks/bench_bisection.py [--box 1 1 1] [--every 1]

(a) ``qdelaunay Qz Fv`` run once per configuration over the 4096 configurations
    (Qhull's merged regions only: no classification, no statistics);
(b) our pipeline without the symmetry reduction: ``tessellate`` on every configuration;
(c) the study with one tessellation per orbit, optimal criterion (what (a) and (b) compute);
(d) the study as ``cospherical study bisection`` runs it: (c) plus the splits of the
    internal-face and internal-edge criteria and their minimal kept sets.

The figures to compare are the ratios (a)/(c), (b)/(c) and (a)/(d).  ``--every N`` times
(a) and (b) on every Nth configuration only and scales them to all of them (a quick run,
as the test suite makes; the ratios are then estimates).  Writes
results/benchmarks/bench_bisection.json (benchmarks/record.py).
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import time

from cospherical import Box, Configuration, tessellate
from cospherical.catalogue import known_name
from cospherical.studies.engine import bisection_codes, run_study
from record import recorded


def timed(function) -> float:
    start = time.perf_counter()
    function()
    return time.perf_counter() - start


def qhull_all(box: Box, codes) -> None:
    for code in codes:
        points = Configuration.from_code(code, box).real_nodes()
        text = f"3\n{len(points)}\n" + "\n".join(" ".join(repr(x) for x in p) for p in points.values()) + "\n"
        subprocess.run(["qdelaunay", "Qz", "Fv"], input=text, capture_output=True, text=True, check=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--box", nargs=3, default=["1", "1", "1"])
    parser.add_argument("--every", type=int, default=1, metavar="N",
                        help="time the baselines (a), (b) on every Nth configuration and scale")
    args = parser.parse_args()
    if args.every < 1:
        parser.error(f"--every {args.every}: must be at least 1")
    if not shutil.which("qdelaunay"):
        raise SystemExit("qdelaunay not found: install qhull-bin (scripts/setup.sh does)")
    with recorded(__file__) as record:
        run(args, record)


def run(args, record) -> None:
    box = Box.parse(args.box)
    codes = bisection_codes()
    known_name("")  # load the shipped catalogue (once per process) before the clock starts
    tessellate(Configuration.from_code("888888888888", box))  # and the compiled walk
    study = timed(lambda: run_study("bisection", box, codes, criteria=("optimal",)))  # (c), cold caches
    full = timed(lambda: run_study("bisection", box, codes))  # (d): the split search runs cold
    sample = codes[::args.every]
    scale = len(codes) / len(sample)
    naive = scale * timed(lambda: [tessellate(Configuration.from_code(code, box)) for code in sample])  # (b)
    qhull = scale * timed(lambda: qhull_all(box, sample))  # (a)
    print(f"bisection study, box {' x '.join(box.texts)}, {len(codes)} configurations"
          + (f" ((a), (b): every {args.every}th, scaled)" if args.every > 1 else ""))
    print(f"  (a) qdelaunay Qz Fv per configuration   {qhull:8.2f} s")
    print(f"  (b) tessellate every configuration      {naive:8.2f} s")
    print(f"  (c) study, one tessellation per orbit   {study:8.2f} s")
    print(f"  (d) study with all three criteria       {full:8.2f} s")
    print(f"  (a)/(c) = {qhull / study:.1f}x   (b)/(c) = {naive / study:.1f}x   (a)/(d) = {qhull / full:.1f}x")
    scaled = f" ((a), (b): every {args.every}th configuration, scaled)" if args.every > 1 else ""
    what = f"box {' x '.join(box.texts)}, {len(codes)} configurations{scaled}"
    record.add(f"(c) study, optimal, vs (a) `qdelaunay Qz Fv` per configuration; {what}",
               f"{study:.2f} s vs {qhull:.2f} s: {qhull / study:.1f}x")
    record.add("(c) vs (b) `tessellate` on every configuration (no symmetry)",
               f"{study:.2f} s vs {naive:.2f} s: {naive / study:.1f}x")
    record.add("(d) study with all three criteria vs (a)", f"{full:.2f} s vs {qhull:.2f} s: {qhull / full:.1f}x")


if __name__ == "__main__":
    main()
