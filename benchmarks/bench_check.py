"""``cospherical check`` of every committed catalogue and pattern table, as a whole process.

    python benchmarks/bench_check.py [--before SRC] [--runs 1]

Runs ``cospherical check catalogue/catalogue.yaml patterns/*.yaml`` (the files ``check``
accepts that the repository commits: the catalogue and the nine pattern tables; the
intersection study's results are summaries, not tables) and reports its CPU seconds (user +
system, of the child process: what a loaded machine inflates least) and wall seconds, the
best of ``--runs``.  ``--before SRC`` (the ``src`` folder of another checkout, e.g. ``git
worktree add /tmp/before <commit>``) runs that version on the same files first, alternating
with this one, so both meet the same load: read the ratio.  The goal is under 10 s of CPU.
Writes results/benchmarks/bench_check.json (benchmarks/record.py).
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

from record import recorded

ROOT = Path(__file__).resolve().parents[1]


def timed(src: Path, files: list[Path]) -> tuple[float, float]:
    """(CPU seconds, wall seconds) of one ``cospherical check`` process on ``files`` with ``src`` first on the path."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "cospherical", "check", *map(str, files)], check=True,
                   stdout=subprocess.DEVNULL, env={**os.environ, "PYTHONPATH": str(src)}, cwd=ROOT)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=Path, metavar="SRC", help="also measure the package in this src folder")
    parser.add_argument("--runs", type=int, default=1, help="best of this many runs of each version")
    args = parser.parse_args()
    if args.before and not (args.before / "cospherical" / "__init__.py").is_file():
        print(f"bench_check.py: error: --before {args.before}: not a src folder with the cospherical package",
              file=sys.stderr)
        sys.exit(2)
    files = [ROOT / "catalogue" / "catalogue.yaml", *sorted((ROOT / "patterns").glob("*.yaml"))]
    versions = ([("before", args.before.resolve())] if args.before else []) + [("this version", ROOT / "src")]
    with recorded(__file__) as record:
        print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; "
              f"{len(files)} files, {sum(f.stat().st_size for f in files) / 2**20:.0f} MB")
        best: dict[str, tuple[float, float]] = {}
        for run in range(args.runs):
            for label, src in versions:  # alternating: both versions meet the same load
                cpu, wall = timed(src, files)
                print(f"run {run + 1}, {label}: {cpu:.2f} s CPU, {wall:.1f} s wall")
                if label not in best or cpu < best[label][0]:
                    best[label] = (cpu, wall)
        for label, (cpu, wall) in best.items():
            record.add(f"{label}: `cospherical check catalogue/catalogue.yaml patterns/*.yaml` ({len(files) - 1} tables)",
                       f"{cpu:.2f} s CPU, {wall:.1f} s wall (best of {args.runs})")
        if args.before:
            ratio = best["this version"][0] / best["before"][0]
            print(f"this version / before: {ratio:.2f} of the CPU seconds")
            record.add("this version / before (CPU seconds)", f"{ratio:.2f}")
        print(f"load average after: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
