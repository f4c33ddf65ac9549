"""`cospherical mesh --out` against TetGen and CGAL on the same vertices, sphere trees of levels 4 to 8, in one run.

    python benchmarks/bench_peers.py [--levels 4,5,6,7,8] [--runs 3] [--radius 0.3]
                                     [--patterns patterns/leaves-1x1x1.yaml] [--peers tetgen,cgal]

Set-up, once (not done by the test command): Debian's ``tetgen`` (``scripts/setup.sh``
installs it) and CGAL's Python bindings, ``.venv/bin/python -m pip install
'cospherical[peers]'`` (the ``cgal`` wheel: CGAL 6 with its ``Epick`` kernel, exact
predicates). For each level L of a sphere refinement of the unit cube
(``--refine sphere:0.5,0.5,0.5,R``, 2:1 balanced), best of ``--runs`` runs each:

(1) ``cospherical mesh --domain 1 1 1 --levels L --refine ... --patterns TABLE --out DIR``,
    the whole process with every default output (``mesh.vtu``, ``report.json``,
    ``mesh.png``) and every default exact check;
(2) the same with ``--dual`` (``dual.npz`` too): the dual's added share of (1);
(3) ``tetgen -Q points.node``: TetGen's Delaunay tetrahedralization of the mesh's vertices,
    the whole process, its own text input and output;
(4) CGAL's ``Delaunay_triangulation_3`` range insert of the same points, timed inside its
    process (the points made before the clock starts), as the issue that asked for this
    table defines it.

Each whole process is measured by the kernel (``os.wait4``: user + system CPU seconds,
peak resident memory); CGAL's insert by ``time.process_time`` in its process. The ratios
mesh / TetGen and mesh / CGAL are of CPU seconds in this one run, so they hold when the
machine's speed drifts; the targets are mesh / TetGen <= 1 at every level, mesh / CGAL <=
1 from level 7 up, the dual's share <= 25 % and a peak at most TetGen's. Level 9 (about
1.8 million vertices: a few minutes and about 2 GB per command) is left out by default on
the 2-core machine; ``--levels 9`` runs it. Writes results/benchmarks/bench_peers.json
(benchmarks/record.py).
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from bench_outputs import _write_node
from record import recorded

CGAL_INSERT = """
import sys, time
import numpy as np
from CGAL.CGAL_Kernel import Point_3
from CGAL.CGAL_Triangulation_3 import Delaunay_triangulation_3
points = [Point_3(x, y, z) for x, y, z in np.load(sys.argv[1]).tolist()]
triangulation = Delaunay_triangulation_3()
start = time.process_time()
triangulation.insert(points)
seconds = time.process_time() - start
print(seconds, triangulation.number_of_finite_cells(), triangulation.number_of_vertices())
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", default="4,5,6,7,8", help="comma-separated tree levels (default 4,5,6,7,8)")
    parser.add_argument("--runs", type=int, default=3, help="runs of each command; the best is shown (default 3)")
    parser.add_argument("--radius", default="0.3")
    parser.add_argument("--patterns", default="patterns/leaves-1x1x1.yaml")
    parser.add_argument("--peers", default="tetgen,cgal", help="which peers to run: tetgen, cgal or both (default)")
    args = parser.parse_args()
    peers = {p.strip() for p in args.peers.split(",") if p.strip()}
    if not peers <= {"tetgen", "cgal"}:
        sys.exit(f"--peers {args.peers}: tetgen, cgal or both")
    tetgen = shutil.which("tetgen")
    if "tetgen" in peers and tetgen is None:
        sys.exit("tetgen not found: scripts/setup.sh installs Debian's tetgen")
    if "cgal" in peers and subprocess.run([sys.executable, "-c", "import CGAL.CGAL_Triangulation_3"],
                                          capture_output=True).returncode:
        sys.exit("CGAL's Python bindings not found: .venv/bin/python -m pip install 'cospherical[peers]'")
    levels = [int(x) for x in args.levels.split(",")]
    with recorded(__file__) as record:
        measure(args, levels, peers, tetgen, record)


def _best(command: list[str], runs: int) -> tuple[float, float, str]:
    """The least CPU seconds over ``runs`` runs of a whole process, its peak GB then, and its stdout."""
    results = [run_usage(command) for _ in range(runs)]
    _, cpu, peak, out = min(results, key=lambda r: r[1])
    return cpu, peak, out


def measure(args, levels: list[int], peers: set[str], tetgen: str | None, record) -> None:
    cospherical = str(Path(sys.executable).with_name("cospherical"))
    machine = _machine()
    print(f"machine: {machine}, {os.cpu_count()} cores; load average {os.getloadavg()[0]:.1f} at the start; "
          f"best of {args.runs} runs")
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench-peers-") as folder:
        folder = Path(folder)
        for level in levels:
            mesh = [cospherical, "mesh", "--domain", "1", "1", "1", "--levels", str(level), "--refine",
                    f"sphere:0.5,0.5,0.5,{args.radius}", "--patterns", args.patterns]
            plain = [run_usage(mesh + ["--out", str(folder / f"L{level}-{k}")]) for k in range(args.runs)]
            dual = [run_usage(mesh + ["--dual", "--out", str(folder / f"L{level}-dual-{k}")]) for k in range(args.runs)]
            _, plain_cpu, plain_peak, text = min(plain, key=lambda run: run[1])
            _, dual_cpu, dual_peak, _ = min(dual, key=lambda run: run[1])
            figures = dict(line.split(": ", 1) for line in text.splitlines() if ": " in line)
            out = folder / f"L{level}-0"
            node = folder / f"L{level}.node"
            _write_node(out / "mesh.vtu", node)
            row = {"level": level, "vertices": int(figures["vertices"].replace(",", "")),
                   "elements": int(figures["elements"].replace(",", "")), "mesh": plain_cpu, "mesh_peak": plain_peak,
                   "dual": dual_cpu, "dual_peak": dual_peak}
            if "tetgen" in peers:
                row["tetgen"], row["tetgen_peak"], _ = _best([tetgen, "-Q", str(node)], args.runs)
                row["tetrahedra"] = int((folder / f"L{level}.1.ele").read_text().split(None, 1)[0])
            if "cgal" in peers:
                points = folder / f"L{level}.npy"
                _save_points(node, points)
                inserts = [subprocess.run([sys.executable, "-c", CGAL_INSERT, str(points)], capture_output=True,
                                          text=True, check=True).stdout.split() for _ in range(args.runs)]
                row["cgal"] = min(float(seconds) for seconds, _, _ in inserts)
                row["cgal_cells"] = int(inserts[0][1])
            for path in folder.glob(f"L{level}*"):
                shutil.rmtree(path) if path.is_dir() else path.unlink()
            rows.append(row)
            print(_line(row), flush=True)
    columns = ["level", "vertices", "elements", "mesh --out s", "peak GB", "tetgen -Q s", "peak GB", "CGAL insert s",
               "mesh / TetGen", "mesh / CGAL", "--dual s", "dual's share"]
    table = [[f"{r['level']}", f"{r['vertices']:,}", f"{r['elements']:,}", f"{r['mesh']:.2f}", f"{r['mesh_peak']:.2f}",
              _figure(r, "tetgen"), _figure(r, "tetgen_peak"), _figure(r, "cgal"),
              f"{r['mesh'] / r['tetgen']:.2f}" if "tetgen" in r else "-",
              f"{r['mesh'] / r['cgal']:.2f}" if "cgal" in r else "-",
              f"{r['dual']:.2f}", f"{100 * (r['dual'] / r['mesh'] - 1):+.0f} %"] for r in rows]
    print(f"\nCPU seconds, best of {args.runs}, sphere trees of radius {args.radius}, table {args.patterns}, on "
          f"{machine}:")
    print(" | ".join(columns))
    for line in table:
        print(" | ".join(line))
    record.add("machine", f"{machine}, {os.cpu_count()} cores")
    record.table(columns, table)


def run_usage(command: list[str]) -> tuple[float, float, float, str]:
    """Wall seconds, CPU seconds (user + system, ``os.wait4``), peak GB and stdout of one whole process.

    The peak is GNU time's (``/usr/bin/time -f %M``), which starts the command from its own small
    process: the peak ``os.wait4`` gives for a child forked from this Python counts the copy of this
    Python the child was before its ``exec`` (some 80 MB, more than TetGen's own peak at level 4)."""
    import time

    with tempfile.NamedTemporaryFile("w+", suffix=".peak") as peak, tempfile.TemporaryFile("w+") as out, \
            tempfile.TemporaryFile("w+") as err:
        start = time.perf_counter()
        process = subprocess.Popen(["/usr/bin/time", "-f", "%M", "-o", peak.name, *command], stdout=out, stderr=err,
                                   text=True)
        _, status, usage = os.wait4(process.pid, 0)
        wall = time.perf_counter() - start
        if os.waitstatus_to_exitcode(status):
            err.seek(0)
            sys.exit(f"{' '.join(command)}: exit {os.waitstatus_to_exitcode(status)}: {err.read().strip()[-500:]}")
        out.seek(0)
        kilobytes = int(Path(peak.name).read_text().split()[-1])
        return wall, usage.ru_utime + usage.ru_stime, kilobytes / 1024**2, out.read()


def _figure(row: dict, key: str) -> str:
    return f"{row[key]:.2f}" if key in row else "-"


def _line(row: dict) -> str:
    parts = [f"L {row['level']}: {row['vertices']:,} vertices, {row['elements']:,} elements; mesh --out "
             f"{row['mesh']:.2f} s ({row['mesh_peak']:.2f} GB), --dual {row['dual']:.2f} s"]
    if "tetgen" in row:
        parts.append(f"tetgen -Q {row['tetgen']:.2f} s ({row['tetgen_peak']:.2f} GB, {row['tetrahedra']:,} tetrahedra)")
    if "cgal" in row:
        parts.append(f"CGAL insert {row['cgal']:.2f} s ({row['cgal_cells']:,} cells)")
    return "; ".join(parts)


def _save_points(node: Path, path: Path) -> None:
    """The ``.node`` file's points as a numpy array (the same floats TetGen reads)."""
    import numpy as np

    points = np.loadtxt(node, skiprows=1, usecols=(1, 2, 3))
    np.save(path, points)


def _machine() -> str:
    """The processor's name, from /proc/cpuinfo."""
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return "unknown processor"


if __name__ == "__main__":
    main()
