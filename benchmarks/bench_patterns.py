"""Big pattern tables: ``study intersection --patterns`` as a whole process, and lookups in its store.

    python benchmarks/bench_patterns.py [--resolution 8] [--order edge] [--jobs 2] [--out DIR]

(a) ``cospherical study intersection --resolution R --patterns --out DIR``: wall time and
    the peak memory of the whole process tree (resident set sizes summed, sampled every
    0.1 s), and the sizes of the YAML table and of its indexed store;
(b) in a fresh process: open the store and look up 1000 random configurations, one at a
    time (wall time per lookup, and the process's peak memory: the store is never read
    whole).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_intersection import tree_rss  # noqa: E402  (one process-tree sampler for the benchmarks)

LOOKUPS = """
import random, resource, sys, time
import cospherical
start = time.perf_counter()
table = cospherical.load_patterns(sys.argv[1])
opened = time.perf_counter() - start
codes = list(table.configurations)  # the index's keys only
random.seed(1)
sample = random.sample(codes, min(1000, len(codes)))
start = time.perf_counter()
for code in sample:
    table.elements(code)
each = (time.perf_counter() - start) / len(sample)
print(opened, each, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--resolution", type=int, default=8)
    parser.add_argument("--order", default="edge")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--out", type=Path, help="where the tables go (default: a temporary folder)")
    args = parser.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="bench-patterns-"))
    command = [sys.executable, "-m", "cospherical", "study", "intersection", "--resolution", str(args.resolution),
               "--order", args.order, "--jobs", str(args.jobs), "--patterns", "--out", str(out)]
    start = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL)
    peak = 0
    while process.poll() is None:
        peak = max(peak, tree_rss(process.pid))
        time.sleep(0.1)
    wall = time.perf_counter() - start
    if process.returncode:
        raise SystemExit(f"the study failed (exit {process.returncode})")
    stem = out / f"intersection-r{args.resolution}-{args.order}-patterns"
    yaml_size, store_size = (Path(f"{stem}{suffix}").stat().st_size / 2**20 for suffix in (".yaml", ".sqlite"))
    print(f"(a) study intersection --resolution {args.resolution} --patterns: {wall:.0f} s wall, "
          f"peak {peak / 2**30:.2f} GiB (process tree); YAML {yaml_size:.0f} MB, store {store_size:.0f} MB")
    opened, each, rss = subprocess.run([sys.executable, "-c", LOOKUPS, f"{stem}.sqlite"], check=True,
                                       capture_output=True, text=True).stdout.split()
    print(f"(b) store: opened in {float(opened) * 1000:.0f} ms, {float(each) * 1000:.2f} ms per lookup, "
          f"peak {float(rss):.0f} MB")


if __name__ == "__main__":
    main()
