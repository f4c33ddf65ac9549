"""The largest tree the docs quote: the whole ``cospherical mesh`` command on the L 10 sphere tree, in one process and in two pieces.

    python benchmarks/bench_scale.py [--levels 10] [--radius 0.3] [--patterns patterns/leaves-1x1x1.yaml]

Two whole processes, as a person runs them, one after the other:

(1) ``cospherical mesh --domain 1 1 1 --levels L --refine sphere:0.5,0.5,0.5,R
    --patterns TABLE --max-leaves 10000000 --out DIR``: one process, every exact check,
    ``mesh.vtu``, ``mesh.png`` and ``report.json`` (the default leaf bound refuses the
    L 10 tree: its estimate from the shape is above half of a 24 GB machine's memory);
(2) the same with ``--partitions 2 --jobs 1``: the two pieces one after the other in one
    process, ``mesh-0.vtu``, ``mesh-1.vtu``, ``mesh.pvtu``.

Each is measured by the kernel when it ends (``os.wait4``: user + system CPU of the
process and every child it waited for, the peak resident memory of the largest of them)
and, every half second while it runs, by the resident memory of its process tree summed
(pages forked children share with their parent count in each). Then the files' sizes and
the report's counts (leaves, vertices, elements, every exact check), and whether the two
reports are the same bytes but for the generator line.

At L 10 each process peaks at several GB and takes minutes of CPU (the last run below
says how many): check ``free -g`` first, or run ``--levels 9``.
Writes results/benchmarks/bench_scale.json (benchmarks/record.py).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from record import ROOT, recorded

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_intersection import tree_rss  # noqa: E402  (one process-tree sampler for the benchmarks)


def run(command: list[str]) -> dict:
    """CPU, wall, peak of the largest process and of the tree summed, for one whole command."""
    start = time.perf_counter()
    with tempfile.TemporaryFile("w+") as err:
        process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=err, text=True)
        peak_tree, done = [0], threading.Event()

        def sample():
            while not done.wait(0.5):
                peak_tree[0] = max(peak_tree[0], tree_rss(process.pid))

        sampler = threading.Thread(target=sample, daemon=True)
        sampler.start()
        _, status, usage = os.wait4(process.pid, 0)
        done.set()
        sampler.join()
        wall = time.perf_counter() - start
        if os.waitstatus_to_exitcode(status) != 0:
            err.seek(0)
            sys.exit(f"{' '.join(command)} failed: {err.read().strip()}")
    return {"wall": wall, "user": usage.ru_utime, "system": usage.ru_stime,
            "peak_gb": usage.ru_maxrss * 1024 / 1e9, "tree_gb": peak_tree[0] / 1e9}


def size(path: Path) -> str:
    n = path.stat().st_size
    return f"{n / 1e6:.1f} MB" if n >= 1e6 else f"{n / 1e3:.0f} kB" if n >= 1e3 else f"{n} bytes"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, default=10)
    parser.add_argument("--radius", type=float, default=0.3)
    parser.add_argument("--patterns", default="patterns/leaves-1x1x1.yaml")
    args = parser.parse_args()
    exe = shutil.which("cospherical", path=str(Path(sys.executable).parent)) or "cospherical"
    base = [exe, "mesh", "--domain", "1", "1", "1", "--levels", str(args.levels),
            "--refine", f"sphere:0.5,0.5,0.5,{args.radius}", "--patterns", str(ROOT / args.patterns),
            "--max-leaves", "10000000"]
    with recorded(__file__) as record, tempfile.TemporaryDirectory() as scratch:
        single, pieces = Path(scratch, "single"), Path(scratch, "pieces")
        shown = " ".join(base[1:]).replace(str(ROOT) + "/", "")
        available = next(int(line.split()[1]) for line in open("/proc/meminfo") if line.startswith("MemAvailable"))
        print(f"memory available at the start: {available / 1e6:.1f} GB")
        a = run([*base, "--out", str(single)])
        report = json.loads((single / "report.json").read_text())
        print(f"(1) cospherical {shown} --out DIR: {a['user'] + a['system']:.1f} s CPU "
              f"({a['user']:.1f} user + {a['system']:.1f} system), {a['wall']:.0f} s wall, "
              f"peak {a['peak_gb']:.2f} GB (process tree summed {a['tree_gb']:.2f} GB)")
        b = run([*base, "--partitions", "2", "--jobs", "1", "--out", str(pieces)])
        print(f"(2) the same with --partitions 2 --jobs 1: {b['user'] + b['system']:.1f} s CPU "
              f"({b['user']:.1f} user + {b['system']:.1f} system), {b['wall']:.0f} s wall, "
              f"peak {b['peak_gb']:.2f} GB (process tree summed {b['tree_gb']:.2f} GB)")

        def strip(path: Path) -> list[str]:
            return [line for line in path.read_text().splitlines() if '"generator"' not in line]

        same = strip(single / "report.json") == strip(pieces / "report.json")
        checks = (f"volume {'exact' if report['volume_ok'] else 'WRONG'}, {report['nonconforming_faces']} nonconforming "
                  f"faces, {report['circumcenters_outside_leaf']} circumcenters outside their leaf, "
                  f"{report['delaunay_violations']} Delaunay violations, {report['delaunay_ties']} ties, "
                  f"{report['regions_retessellated']} regions re-tessellated")
        tree = (f"{report['leaves']:,} leaves, {report['vertices']:,} vertices, {report['elements']:,} elements, "
                f"{report['configurations']} configurations ({report['configurations_from_table']} from the table)")
        print(f"the tree: {tree}; {checks}")
        print(f"report.json of (2) the same as (1)'s but for the generator line: {same}")
        record.add(f"the tree ({shown})", f"{tree}; {checks}")
        record.table(["command", "CPU (user + system)", "wall", "peak, largest process", "peak, process tree summed", "files"], [
            ["one process, --out DIR", f"{a['user'] + a['system']:.1f} s ({a['user']:.1f} + {a['system']:.1f})",
             f"{a['wall']:.0f} s", f"{a['peak_gb']:.2f} GB", f"{a['tree_gb']:.2f} GB",
             ", ".join(f"{name} {size(single / name)}" for name in ("mesh.vtu", "mesh.png", "report.json"))],
            ["--partitions 2 --jobs 1 --out DIR", f"{b['user'] + b['system']:.1f} s ({b['user']:.1f} + {b['system']:.1f})",
             f"{b['wall']:.0f} s", f"{b['peak_gb']:.2f} GB", f"{b['tree_gb']:.2f} GB",
             ", ".join(f"{name} {size(pieces / name)}" for name in ("mesh-0.vtu", "mesh-1.vtu", "mesh.pvtu"))
             + f"; report.json {'the same as the single process’s but for the generator line' if same else 'DIFFERS'}"],
        ])


if __name__ == "__main__":
    main()
