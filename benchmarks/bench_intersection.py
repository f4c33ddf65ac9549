"""The intersection study at 1/16 against the naive per-configuration pipeline, timed in this one run.

    python benchmarks/bench_intersection.py [--order edge] [--jobs 2] [--sample 300]

(a) the whole study as ``cospherical study intersection`` runs it: every
    configuration at 1/16 (3,375,000), one compiled tessellation per orbit, each
    distinct element classified and split once, all three criteria, on --jobs
    local processes; wall time and the peak memory of the whole process tree
    (this process and its workers, resident set sizes summed, sampled every 0.1 s);
(b) the naive pipeline, estimated on a random sample of configurations in the same
    run: ``tessellate`` on each configuration plus the splits of each of its
    elements under both criteria (cold caches), scaled to every configuration and
    divided by the same number of cores;
(c) ``qdelaunay Qz Fv`` once per configuration (Qhull's merged regions only), estimated
    on the same sample;
(d) one ``tessellate`` call on an intersection configuration, median after warm-up,
    with the compiled walk and with the Python walk.

Writes results/benchmarks/bench_intersection.json (benchmarks/record.py).
"""

from __future__ import annotations

import argparse
import os
import random
import shutil
import statistics
import subprocess
import threading
import time

from cospherical import Configuration, tessellate
from cospherical.studies.intersection import intersection_codes, run_intersection
from record import recorded


def tree_pids(pid: int) -> list[int]:
    """A process and all its descendants (Linux /proc)."""
    children: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as handle:
                    fields = handle.read().rsplit(")", 1)[1].split()
                children.setdefault(int(fields[1]), []).append(int(entry))
            except OSError:
                continue
    found, todo = [], [pid]
    while todo:
        p = todo.pop()
        found.append(p)
        todo.extend(children.get(p, []))
    return found


def tree_rss(pid: int) -> int:
    """Resident bytes of a process and all its descendants (pages shared by forked workers count in each)."""
    total = 0
    for p in tree_pids(pid):
        try:
            with open(f"/proc/{p}/statm") as handle:
                total += int(handle.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
        except OSError:
            continue
    return total


def tree_pss(pid: int) -> int:
    """Proportional set size of a process tree: the memory it really holds, a page shared
    by n processes counted 1/n in each (Linux /proc/PID/smaps_rollup)."""
    total = 0
    for p in tree_pids(pid):
        try:
            with open(f"/proc/{p}/smaps_rollup") as handle:
                total += next(int(line.split()[1]) * 1024 for line in handle if line.startswith("Pss:"))
        except (OSError, StopIteration):
            continue
    return total


class PeakMemory:
    """Sample the process tree's resident memory in a thread; ``peak`` in bytes."""

    def __enter__(self):
        self.peak, self._stop = 0, threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()
        return self

    def _run(self) -> None:
        while not self._stop.is_set():
            self.peak = max(self.peak, tree_rss(os.getpid()))
            self._stop.wait(0.1)

    def __exit__(self, *exc) -> None:
        self._stop.set()
        self._thread.join()


def codes_of(digits) -> list[str]:
    return ["".join("%x" % d for d in row) for row in digits]


def naive(code: str) -> None:
    from cospherical.catalogue import element_options

    tess = tessellate(Configuration.from_code(code), backend="compiled")  # the walk at its fastest
    for element in tess.elements:
        for criterion in ("internal_faces", "internal_edges_and_faces"):
            element_options(tess, element, criterion)


def qhull(code: str) -> None:
    points = Configuration.from_code(code).real_nodes()
    text = f"3\n{len(points)}\n" + "\n".join(" ".join(repr(x) for x in p) for p in points.values()) + "\n"
    subprocess.run(["qdelaunay", "Qz", "Fv"], input=text, capture_output=True, text=True, check=True)


def median_call(configurations, backend: str) -> float:
    for cfg in configurations[:50]:
        tessellate(cfg, backend)  # warm-up: compiled code loaded, caches filled
    times = []
    for cfg in configurations:
        start = time.perf_counter()
        tessellate(cfg, backend)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--order", default="edge")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--sample", type=int, default=300, help="configurations timed for the estimates (b), (c)")
    parser.add_argument("--resolution", type=int, default=16, choices=(2, 4, 8, 16),
                        help="positions at multiples of 1/R (default 16, the paper's; smaller for a quick check)")
    args = parser.parse_args()
    if not shutil.which("qdelaunay"):
        raise SystemExit("qdelaunay not found: install qhull-bin (scripts/setup.sh does)")
    with recorded(__file__) as record:
        measure(args, record)


def measure(args, record) -> None:
    start = time.perf_counter()
    run_intersection(2, jobs=1)  # compiles (or loads) the numba kernels once, before the clock
    warm = time.perf_counter() - start

    with PeakMemory() as memory:
        start = time.perf_counter()
        summary = run_intersection(args.resolution, args.order, jobs=args.jobs)
        wall = time.perf_counter() - start
    configurations = summary["configurations"]

    digits = intersection_codes(args.resolution, args.order)
    rng = random.Random(2026)
    sample = codes_of(digits[sorted(rng.sample(range(len(digits)), args.sample))])
    start = time.perf_counter()
    for code in sample:
        naive(code)
    per_naive = (time.perf_counter() - start) / len(sample)
    start = time.perf_counter()
    for code in sample:
        qhull(code)
    per_qhull = (time.perf_counter() - start) / len(sample)
    naive_wall = per_naive * configurations / args.jobs
    qhull_wall = per_qhull * configurations / args.jobs

    single = [Configuration.from_code(code) for code in codes_of(digits[rng.sample(range(len(digits)), 1000)])]
    fast, slow = median_call(single, "compiled"), median_call(single, "python")

    optimal = summary["criteria"]["optimal"]
    print(f"intersection study at 1/{args.resolution}, insertion order {args.order}, {args.jobs} processes")
    print(f"  configurations {configurations:,}, orbits {summary['orbits']:,}, elements {optimal['total']:,}, "
          f"types {optimal['types_count']}")
    print(f"  (a) whole study, all three criteria       {wall:8.1f} s   {configurations / wall:,.0f} configurations/s"
          f"   peak memory {memory.peak / 2**30:.2f} GiB   (kernels loaded beforehand in {warm:.1f} s)")
    print(f"  (b) naive pipeline, estimated             {naive_wall:8.0f} s   ({per_naive * 1e3:.2f} ms per "
          f"configuration on {len(sample)} sampled)")
    print(f"  (c) qdelaunay per configuration, estimated {qhull_wall:7.0f} s   ({per_qhull * 1e3:.2f} ms each)")
    print(f"  (b)/(a) = {naive_wall / wall:.0f}x   (c)/(a) = {qhull_wall / wall:.0f}x")
    print(f"  (d) tessellate() median: compiled walk {fast * 1e3:.3f} ms, Python walk {slow * 1e3:.3f} ms "
          f"({slow / fast:.1f}x)")
    what = (f"intersection study at 1/{args.resolution} ({configurations:,} configurations, {summary['orbits']:,} "
            f"orbits), order {args.order}, all three criteria, {args.jobs} processes")
    record.add(f"(a) {what}", f"{wall:.1f} s wall, {configurations / wall:,.0f} configurations/s, "
                              f"peak {memory.peak / 2**30:.2f} GiB (process tree)")
    record.add(f"(b) the naive pipeline (`tessellate` + splits per configuration), estimated on {len(sample)}",
               f"{naive_wall:.0f} s: {naive_wall / wall:.0f}x")
    record.add("(c) `qdelaunay Qz Fv` once per configuration, estimated on the same sample",
               f"{qhull_wall:.0f} s: {qhull_wall / wall:.0f}x")
    record.add("(d) one `tessellate` call, 1/16-type configuration, median of 1000",
               f"compiled walk {fast * 1e3:.3f} ms, Python walk {slow * 1e3:.3f} ms")


if __name__ == "__main__":
    main()
