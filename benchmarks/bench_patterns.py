"""Big pattern tables: ``study intersection --patterns`` as a whole process, and lookups in its store.

    python benchmarks/bench_patterns.py [--resolution 8] [--order edge] [--jobs 2] [--out DIR]

(a) ``cospherical study intersection --resolution R --format json``, the study alone, as a
    whole process: wall time and peak memory of the process tree, sampled every 0.1 s, as
    proportional set sizes (what the tree holds: pages that forked workers share with
    their parent counted once) and as resident set sizes summed (those pages counted in
    every process);
(b) the same with ``--patterns --out DIR``: wall time, peak memory, and the sizes of the
    table's files (the store; the YAML too up to R = 4); the table's own time is (b) - (a);
(c) the baseline, in this run: the table made as before, one tessellation (compiled walk)
    and one split per criterion for each orbit representative, timed in this process on
    every k-th representative and scaled to all of them, against (b) - (a);
(d) in a fresh process: open the store and look up 1000 random configurations, one at a
    time (wall time per lookup, and the process's peak memory: the store is never read
    whole).

Writes results/benchmarks/bench_patterns.json (benchmarks/record.py).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from record import recorded

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_intersection import tree_pss, tree_rss  # noqa: E402  (one process-tree sampler for the benchmarks)

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


def naive_seconds(summary: dict, resolution: int, order: str, sample: int = 2000) -> float:
    """The table as it was made before, timed on ``sample`` representatives, scaled to all."""
    from cospherical import Configuration, tessellate
    from cospherical.catalogue import split_tessellation
    from cospherical.core.symmetry import key_code
    from cospherical.formats.patterns import configuration_line
    from cospherical.studies.intersection import orbits

    reps, _, _ = orbits(resolution, order)
    kept = {c: frozenset(data["kept"]) for c, data in summary["criteria"].items() if c != "optimal"}
    codes = reps[:: max(1, len(reps) // sample)].tolist()
    start = time.perf_counter()
    for code in map(key_code, codes):
        tess = tessellate(Configuration.from_code(code), backend="compiled")  # the bulk path
        split = {c: split_tessellation(tess, types, c)[0] for c, types in kept.items()}
        configuration_line(code, tess.fvm_adequate, {"optimal": tess, **split})
    return (time.perf_counter() - start) / len(codes) * len(reps)


def run(command) -> tuple[float, str]:
    """Wall time and peak process-tree memory of a command (proportional, and resident summed)."""
    start = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL)
    pss = rss = 0
    while process.poll() is None:
        pss, rss = max(pss, tree_pss(process.pid)), max(rss, tree_rss(process.pid))
        time.sleep(0.1)
    if process.returncode:
        raise SystemExit(f"{' '.join(command)} failed (exit {process.returncode})")
    return time.perf_counter() - start, f"peak {pss / 2**30:.2f} GiB (process tree, PSS; resident sum {rss / 2**30:.2f} GiB)"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--resolution", type=int, default=8)
    parser.add_argument("--order", default="edge")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--out", type=Path, help="where the tables go (default: a temporary folder)")
    args = parser.parse_args()
    with recorded(__file__) as record:
        measure(args, record)


def measure(args, record) -> None:
    out = args.out or Path(tempfile.mkdtemp(prefix="bench-patterns-"))
    study = [sys.executable, "-m", "cospherical", "study", "intersection", "--resolution", str(args.resolution),
             "--order", args.order, "--jobs", str(args.jobs)]
    print(f"load average before: {os.getloadavg()[0]:.1f}")
    alone, alone_peak = run([*study, "--format", "json"])
    print(f"(a) study intersection --resolution {args.resolution}, the study alone: {alone:.0f} s wall, {alone_peak}")
    record.add(f"(a) `study intersection --resolution {args.resolution}`, the study alone", f"{alone:.0f} s wall, {alone_peak}")
    wall, peak = run([*study, "--patterns", "--out", str(out)])
    stem = out / f"intersection-r{args.resolution}-{args.order}-patterns"
    sizes = ", ".join(f"{suffix[1:]} {Path(f'{stem}{suffix}').stat().st_size / 1e6:.0f} MB"
                      for suffix in (".sqlite", ".yaml") if Path(f"{stem}{suffix}").exists())
    print(f"(b) the same with --patterns: {wall:.0f} s wall ({wall - alone:.0f} s for the table and the other --out files), "
          f"{peak}; {sizes}")
    record.add("(b) the same with `--patterns`", f"{wall:.0f} s wall ({wall - alone:.0f} s for the table), {peak}; {sizes}")
    summary = json.loads((out / f"intersection-r{args.resolution}-{args.order}.json").read_text())
    naive = naive_seconds(summary, args.resolution, args.order)
    print(f"(c) the table one tessellation per representative (before), estimated: {naive:.0f} s in one process, "
          f"{naive / args.jobs:.0f} s on {args.jobs}: {naive / args.jobs / max(wall - alone, 1e-9):.0f}x the table's time now")
    record.add("(c) the table made one tessellation per representative (the old way), estimated",
               f"{naive / args.jobs:.0f} s on {args.jobs} processes: {naive / args.jobs / max(wall - alone, 1e-9):.0f}x")
    opened, each, rss = subprocess.run([sys.executable, "-c", LOOKUPS, f"{stem}.sqlite"], check=True,
                                       capture_output=True, text=True).stdout.split()
    print(f"(d) store: opened in {float(opened) * 1000:.0f} ms, {float(each) * 1000:.2f} ms per lookup, "
          f"peak {float(rss):.0f} MB; load average after: {os.getloadavg()[0]:.1f}")
    record.add("(d) a lookup in the store, fresh process",
               f"opened in {float(opened) * 1000:.0f} ms, {float(each) * 1000:.2f} ms per lookup, peak {float(rss):.0f} MB")


if __name__ == "__main__":
    main()
