"""Whole processes, as a user meets them, all measured in this one run.

    python benchmarks/bench_startup.py [--runs 7] [--before SRC] [--every 1] [--tables '*.yaml']

(1) ``cospherical tessellate --box 1 1 1 --code 800000000000``: median wall time of a
    whole process (the target is 0.3 s);
(2) ``cospherical study bisection --box 1 1 1 --format json`` as a whole process, against
    ``qdelaunay Qz Fv`` run once per configuration over the 4096 configurations (a
    process each, as a script would): the ratio (the target is >= 10x);
(3) ``cospherical.load_patterns("patterns/bisection-1x1x1.yaml")`` and one lookup, in a
    fresh interpreter: wall time from start to the answer, and peak memory (targets:
    0.5 s, 150 MB);
(4) the same file read whole by PyYAML (C loader), for comparison;
(5) ``cospherical check catalogue/catalogue.yaml patterns/*.yaml`` as a whole process (the
    target is 15 s).

Wall times on a shared machine vary; the script prints the median of ``--runs`` runs
and the machine's load average beside them.  ``--before SRC`` (the ``src`` folder of
another checkout, e.g. ``git worktree add /tmp/before <commit>``) measures that
version too, in the same run, with its own pattern table.  ``--every N`` runs qdelaunay on
every Nth configuration only and scales its time to all 4096, PyYAML (4) reads every Nth
entry only, and ``--tables`` narrows (5) to the tables matching a pattern: a quick run, as
the test suite makes.  Writes results/benchmarks/bench_startup.json (benchmarks/record.py).
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

from record import recorded

ROOT = Path(__file__).resolve().parents[1]
COSPHERICAL = [sys.executable, "-m", "cospherical"]

LOAD = """
import resource, sys, time
start = time.perf_counter()
import cospherical
table = cospherical.load_patterns(sys.argv[1])
table.elements("800000000000")
print(time.perf_counter() - start, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
"""

PYYAML = """
import resource, sys, time
start = time.perf_counter()
import yaml
every = int(sys.argv[2])
with open(sys.argv[1]) as handle:
    if every == 1:
        yaml.load(handle, Loader=yaml.CSafeLoader)
    else:  # the header and every Nth entry (one line each)
        lines = handle.read().split("\\n")
        body = lines.index("configurations:") + 1
        yaml.load("\\n".join(lines[:body] + lines[body::every]), Loader=yaml.CSafeLoader)
print(time.perf_counter() - start, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
"""


def wall(command, env=None) -> float:
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, env=env)
    return time.perf_counter() - start


def qhull_all(every: int) -> float:
    """Seconds of ``qdelaunay`` over every ``every``-th bisection configuration, scaled to all."""
    from cospherical import Configuration
    from cospherical.studies.engine import bisection_codes

    codes = bisection_codes()
    inputs = []
    for code in codes[::every]:
        points = Configuration.from_code(code).real_nodes()
        inputs.append(f"3\n{len(points)}\n" + "\n".join(" ".join(repr(x) for x in p) for p in points.values()) + "\n")
    start = time.perf_counter()
    for text in inputs:
        subprocess.run(["qdelaunay", "Qz", "Fv"], input=text, capture_output=True, text=True, check=True)
    return (time.perf_counter() - start) * len(codes) / len(inputs)


def measure(label: str, env, root: Path, runs: int, qhull: float, tables: str, record) -> None:
    print(f"--- {label}")
    tessellate = [wall([*COSPHERICAL, "tessellate", "--box", "1", "1", "1", "--code", "800000000000"], env)
                  for _ in range(runs)]
    print(f"(1) tessellate, whole process: median {statistics.median(tessellate):.3f} s "
          f"(min {min(tessellate):.3f}, max {max(tessellate):.3f})")
    record.add(f"{label}: (1) `cospherical tessellate --box 1 1 1 --code 800000000000`, whole process",
               f"{statistics.median(tessellate):.3f} s wall, median of {runs}")
    study = [wall([*COSPHERICAL, "study", "bisection", "--box", "1", "1", "1", "--format", "json"], env)
             for _ in range(runs if runs < 3 else max(3, runs // 2))]
    print(f"(2) study bisection, whole process: median {statistics.median(study):.3f} s; "
          f"qdelaunay x 4096 processes: {qhull:.2f} s; ratio {qhull / statistics.median(study):.1f}x")
    record.add(f"{label}: (2) `cospherical study bisection --box 1 1 1 --format json` vs `qdelaunay Qz Fv` x 4096",
               f"{statistics.median(study):.3f} s vs {qhull:.2f} s wall: {qhull / statistics.median(study):.1f}x")
    table = root / "patterns" / "bisection-1x1x1.yaml"
    loads = [subprocess.run([sys.executable, "-c", LOAD, str(table)], check=True, capture_output=True, text=True,
                            env=env).stdout.split() for _ in range(max(1, runs if label == "this version" else 1))]
    seconds = statistics.median(float(s) for s, _ in loads)
    print(f"(3) load_patterns + one lookup, fresh process: median {seconds:.3f} s, "
          f"peak {max(float(m) for _, m in loads):.0f} MB ({table.stat().st_size / 2**20:.1f} MB file)")
    record.add(f"{label}: (3) `load_patterns(\"patterns/bisection-1x1x1.yaml\")` + one lookup, fresh process",
               f"{seconds:.3f} s wall, peak {max(float(m) for _, m in loads):.0f} MB")
    files = [root / "catalogue" / "catalogue.yaml", *sorted((root / "patterns").glob(tables))]
    seconds = wall([*COSPHERICAL, "check", *map(str, files)], env)
    print(f"(5) check catalogue/catalogue.yaml patterns/{tables} ({len(files) - 1} tables), whole process: "
          f"{seconds:.1f} s")
    record.add(f"{label}: (5) `cospherical check catalogue/catalogue.yaml patterns/{tables}` ({len(files) - 1} tables)",
               f"{seconds:.1f} s wall")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--before", type=Path, metavar="SRC", help="also measure the package in this src folder")
    parser.add_argument("--every", type=int, default=1, metavar="N",
                        help="run qdelaunay on every Nth configuration and scale its time")
    parser.add_argument("--tables", default="*.yaml", metavar="GLOB", help="the pattern tables (5) checks")
    args = parser.parse_args()
    if args.every < 1:
        parser.error(f"--every {args.every}: must be at least 1")
    if args.before and not (args.before / "cospherical" / "__init__.py").is_file():
        # PYTHONPATH pointing nowhere would measure this version as "before" without a word
        print(f"bench_startup.py: error: --before {args.before}: not a src folder with the cospherical package",
              file=sys.stderr)
        sys.exit(2)
    if not shutil.which("qdelaunay"):
        raise SystemExit("qdelaunay not found: install qhull-bin (scripts/setup.sh does)")
    with recorded(__file__) as record:
        run(args, record)


def run(args, record) -> None:
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    qhull = qhull_all(args.every)
    if args.before:
        env = {**os.environ, "PYTHONPATH": str(args.before.resolve())}
        wall([*COSPHERICAL, "tessellate", "--box", "1", "1", "1", "--code", "800000000000"], env)  # numba cache
        measure(f"before: {args.before}", env, args.before.resolve().parent, args.runs, qhull, args.tables, record)
    measure("this version", None, ROOT, args.runs, qhull, args.tables, record)
    table = ROOT / "patterns" / "bisection-1x1x1.yaml"
    s, m = subprocess.run([sys.executable, "-c", PYYAML, str(table), str(args.every)], check=True,
                          capture_output=True, text=True).stdout.split()
    if args.every == 1:
        print(f"(4) PyYAML (C loader) reading this version's file whole: {float(s):.2f} s, peak {float(m):.0f} MB")
        record.add("(4) PyYAML (C loader) reading that file whole", f"{float(s):.2f} s, peak {float(m):.0f} MB")
    else:
        print(f"(4) PyYAML (C loader) reading every {args.every}th entry of this version's file: {float(s):.2f} s "
              f"(x {args.every}: {float(s) * args.every:.1f} s), peak {float(m):.0f} MB")
    print(f"load average after: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
