"""Where `cospherical mesh --out` spends its CPU, phase by phase, beside each phase's floor, in one run.

    python benchmarks/bench_phases.py [--levels 7,8] [--runs 3] [--radius 0.3]
                                      [--patterns patterns/leaves-1x1x1.yaml]

For each level, ``--runs`` fresh interpreters (a phase's first run in a process is the one a
user pays: fresh memory, cold caches) each mesh the sphere tree of the unit cube from the leaf
table and write its outputs as ``cospherical mesh --out`` does (``build_mesh``, then
``mesh.vtu``, ``mesh.png``, ``report.json``), timing every phase with ``time.process_time``
(this process's CPU seconds: what the machine's load does not inflate); the least of the runs
is shown. Beside them, the floors the issue asked for:

- the outputs alone: the bytes of ``mesh.vtu``'s arrays and the time numpy takes to write them
  raw (``ndarray.tofile``), and zlib at its fastest level (1) on the same arrays, which the file
  must hold byte for byte (the time of the compressed file's floor);
- the exact checks alone: volume, conformity, circumcenters and the global Delaunay check, run
  again on the finished mesh.

Writes results/benchmarks/bench_phases.json (benchmarks/record.py).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

from record import recorded

PHASES = """
import json, os, sys, tempfile, time
# the pipeline's own clock (time.perf_counter) made this process's CPU clock: its stages in CPU seconds
time.perf_counter = time.process_time
start = time.process_time()
from cospherical.api.mesh import build_mesh, default_cut
from cospherical.core.configuration import Box
level, radius, patterns, folder = int(sys.argv[1]), sys.argv[2], sys.argv[3], sys.argv[4]
seconds = {"imports (the API's)": time.process_time() - start}
mesh = build_mesh(Box.parse(["1", "1", "1"]), levels=level, refine=[f"sphere:0.5,0.5,0.5,{radius}"],
                  patterns=patterns)
seconds.update(mesh.report.timings)
path = lambda name: os.path.join(folder, name)
clock = time.process_time()
from cospherical.formats.mesh import vtu_grid, write_report, write_vtu  # where the command imports them
point_data, cell_data = mesh._vtu_data(False)
write_vtu(mesh.assembled, path("mesh.vtu"), point_data=point_data, cell_data=cell_data,
          leaves=mesh._result.source.leaf_order)
seconds["mesh.vtu"] = time.process_time() - clock
clock = time.process_time()
from cospherical.outputs.mesh_picture import cut_png
cut_png(mesh.assembled, path("mesh.png"), at=default_cut(mesh._result.source.shapes, mesh.box), title="phases")
seconds["mesh.png"] = time.process_time() - clock
clock = time.process_time()
write_report(mesh.report.to_dict(), path("report.json"))
seconds["report.json"] = time.process_time() - clock
# floors, on the finished mesh
from cospherical.formats.vtu import _compressed, narrow
from cospherical.mesh import checks
clock = time.process_time()
grid = vtu_grid(mesh.assembled, point_data, cell_data, mesh._result.source.leaf_order)
seconds["mesh.vtu: its arrays"] = time.process_time() - clock
arrays = [grid.points, grid.types, grid.connectivity, grid.offsets, grid.faces, grid.faceoffsets,
          *grid.point_data.values(), *grid.cell_data.values(), *grid.field_data.values()]
arrays = [narrow(a) if a.dtype.kind == "i" else a for a in arrays if a is not None]
clock = time.process_time()
with open(path("raw.bin"), "wb") as handle:
    for array in arrays:
        array.tofile(handle)
seconds["floor: arrays written raw (numpy)"] = time.process_time() - clock
clock = time.process_time()
compressed = sum(len(block) for block in _compressed(arrays, None))  # CPU of every thread (process_time)
seconds["floor: arrays deflated (zlib level 1)"] = time.process_time() - clock
m = mesh.assembled
clock = time.process_time()
checks.check_volume(m); checks.check_conformity(m); checks.check_circumcenters(m); checks.check_delaunay(m)
seconds["floor: the exact checks alone, again"] = time.process_time() - clock
seconds["total (this process)"] = time.process_time()
print(json.dumps({"seconds": seconds, "raw_bytes": sum(a.nbytes for a in arrays), "deflated_bytes": compressed,
                  "vtu_bytes": os.path.getsize(path("mesh.vtu")), "vertices": len(m.vertices), "elements": len(m)}))
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", default="7,8", help="comma-separated tree levels (default 7,8)")
    parser.add_argument("--runs", type=int, default=3, help="fresh processes per level; the least is shown")
    parser.add_argument("--radius", default="0.3")
    parser.add_argument("--patterns", default="patterns/leaves-1x1x1.yaml")
    args = parser.parse_args()
    levels = [int(x) for x in args.levels.split(",")]
    with recorded(__file__) as record:
        results = {}
        for level in levels:
            runs = []
            for _ in range(args.runs):
                with tempfile.TemporaryDirectory(prefix="bench-phases-") as folder:
                    out = subprocess.run([sys.executable, "-c", PHASES, str(level), args.radius, args.patterns,
                                          folder], capture_output=True, text=True, check=True).stdout
                runs.append(json.loads(out.splitlines()[-1]))
            best = dict(runs[0])
            best["seconds"] = {k: min(run["seconds"][k] for run in runs) for k in runs[0]["seconds"]}
            results[level] = best
            print(f"L {level}: {best['vertices']:,} vertices, {best['elements']:,} elements; mesh.vtu "
                  f"{best['vtu_bytes'] / 1e6:.1f} MB, its arrays {best['raw_bytes'] / 1e6:.1f} MB raw, "
                  f"{best['deflated_bytes'] / 1e6:.1f} MB deflated", flush=True)
        names = list(results[levels[0]]["seconds"])
        columns = ["phase (CPU s, least of runs)"] + [f"L {level}" for level in levels]
        table = [[name] + [f"{results[level]['seconds'][name]:.3f}" for level in levels] for name in names]
        print(" | ".join(columns))
        for row in table:
            print(" | ".join(row))
        record.table(columns, table)


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).parent))
    main()
