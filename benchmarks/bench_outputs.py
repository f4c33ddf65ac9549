"""The whole ``cospherical mesh`` command with every output, against TetGen on the same vertices, in one run.

    python benchmarks/bench_outputs.py [--levels 8] [--radius 0.3] [--patterns patterns/leaves-1x1x1.yaml]

Whole processes, as a person runs them, each measured by the kernel (``os.wait4``:
user + system CPU, peak resident memory) and by the wall clock:

(1) ``cospherical mesh --domain 1 1 1 --levels L --refine sphere:0.5,0.5,0.5,R
    --patterns TABLE`` without ``--out`` (tree, assembly, every exact check, report);
(2) the same with ``--out DIR``: ``mesh.vtu``, ``mesh.png`` and ``report.json`` too;
(3) TetGen (Debian's ``tetgen``, its version printed) on the same vertices, read from
    the VTU just written into a ``.node`` file (not timed): ``tetgen -Q points.node``,
    a Delaunay tetrahedralization with its own text input and output;
(4) reading ``mesh.vtu`` back in a fresh interpreter with VTK
    (``vtkXMLUnstructuredGridReader``, what ParaView uses) and with meshio, timed from
    the call to the mesh in memory (the imports apart).

(5) meshio reading the same grid without its polyhedra (``standard.vtu``: the same
    points, every standard cell, written by ``formats.vtu.write_grid``).

The targets: (2) at most the CPU of (3); VTK read < 3 s; meshio read < 10 s; peak of
(2) < 1.5 GB.  meshio 5.3.5 cannot read a grid that mixes ``VTK_POLYHEDRON`` with other
cells in any layout: ``_organize_cells`` in ``meshio/vtu/_vtu.py`` raises "Cannot handle
combinations of polyhedra with other cells" when one cell of a piece is type 42 and
another is not, and "Implementation assumes single set of cells" for polyhedra spread over
several pieces; ``VTK_CONVEX_POINT_SET`` (41), valid VTK for a convex element, is not in
its ``vtk_to_meshio_type`` table, so those cells would be dropped with a warning.  (4)
then says so, and (5) is meshio's time on the standard cells.  Writes
results/benchmarks/bench_outputs.json (benchmarks/record.py).
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from record import recorded

READ = """
import sys, time
path, reader = sys.argv[1], sys.argv[2]
if reader == "vtk":
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
    start, cpu = time.perf_counter(), time.process_time()
    r = vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    cells = r.GetOutput().GetNumberOfCells()
else:
    import meshio
    start, cpu = time.perf_counter(), time.process_time()
    try:
        cells = sum(len(b.data) for b in meshio.read(path).cells)
    except Exception as error:
        print(f"refused: {type(error).__name__}: {error}")
        sys.exit(0)
print(f"{time.perf_counter() - start:.2f} s wall {time.process_time() - cpu:.2f} s cpu, {cells:,} cells")
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, default=8)
    parser.add_argument("--radius", default="0.3")
    parser.add_argument("--patterns", default="patterns/leaves-1x1x1.yaml")
    args = parser.parse_args()
    tetgen = shutil.which("tetgen")
    if tetgen is None:
        sys.exit("tetgen not found: apt-get install tetgen")
    version = subprocess.run(["dpkg-query", "-W", "-f", "${Version}", "tetgen"], capture_output=True,
                             text=True, check=False).stdout.strip() or "unknown"
    cospherical = str(Path(sys.executable).with_name("cospherical"))
    mesh = [cospherical, "mesh", "--domain", "1", "1", "1", "--levels", str(args.levels), "--refine",
            f"sphere:0.5,0.5,0.5,{args.radius}", "--patterns", args.patterns]
    with recorded(__file__) as record:
        measure(args, mesh, tetgen, version, record)


def measure(args, mesh, tetgen, version, record) -> None:
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench-outputs-") as folder:
        folder = Path(folder)
        wall, cpu, peak, out = run_usage(mesh)
        figures = dict(line.split(": ", 1) for line in out.splitlines() if ": " in line)
        rows.append(("cospherical mesh (no --out)", wall, cpu, peak))
        wall, cpu, peak, _ = run_usage(mesh + ["--out", str(folder / "out")])
        rows.append(("cospherical mesh --out (vtu, png, report)", wall, cpu, peak))
        vtu = folder / "out" / "mesh.vtu"
        size = vtu.stat().st_size
        node = folder / "points.node"
        _write_node(vtu, node)
        wall, cpu, peak, _ = run_usage([tetgen, "-Q", str(node)])
        tetrahedra = int((folder / "points.1.ele").read_text().split(None, 1)[0])
        rows.append((f"tetgen -Q (Debian tetgen {version}), same vertices", wall, cpu, peak))
        reads = {reader: run_usage([sys.executable, "-c", READ, str(vtu), reader])[3].strip()
                 for reader in ("vtk", "meshio")}
        standard = folder / "standard.vtu"
        kept = _write_standard(vtu, standard)
        reads[f"meshio, without the polyhedra ({kept:,} standard cells)"] = \
            run_usage([sys.executable, "-c", READ, str(standard), "meshio"])[3].strip()
        shutil.rmtree(folder / "out")
        stages = _stages(mesh + ["--out", str(folder / "out")])
    print(f"sphere octree L {args.levels}, R {args.radius}: {figures.get('leaves')} leaves, "
          f"{figures.get('vertices')} vertices, {figures.get('elements')} elements; TetGen: {tetrahedra:,} tetrahedra")
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; mesh.vtu {size / 1e6:.1f} MB")
    print(f"{'':58s} {'CPU s':>8s} {'wall s':>8s} {'peak GB':>8s}")
    for name, wall, cpu, peak in rows:
        print(f"{name:58s} {cpu:8.2f} {wall:8.2f} {peak:8.2f}")
    print(f"ratio: cospherical mesh --out CPU / TetGen CPU = {rows[1][2] / rows[2][2]:.2f} (target <= 1)")
    for reader, text in reads.items():
        print(f"reading mesh.vtu with {reader}: {text}")
    print(f"stages of the command with --out, CPU s: {stages}")
    record.add(f"sphere tree L {args.levels}, R {args.radius}", f"{figures.get('leaves')} leaves, "
               f"{figures.get('vertices')} vertices, {figures.get('elements')} elements; mesh.vtu {size / 1e6:.1f} MB")
    for name, wall, cpu, peak in rows:
        record.add(name, f"{cpu:.2f} s CPU, {wall:.2f} s wall, peak {peak:.2f} GB")
    record.add("`cospherical mesh --out` CPU / TetGen CPU", f"{rows[1][2] / rows[2][2]:.2f} "
               f"(TetGen: {tetrahedra:,} tetrahedra)")
    for reader, text in reads.items():
        record.add(f"reading mesh.vtu with {reader}", text)
    record.add("stages of the command with --out (CPU s, one more run)", stages)


def run_usage(command: list[str]) -> tuple[float, float, float, str]:
    """Wall seconds, CPU seconds (user + system), peak GB and stdout of one whole process (``os.wait4``)."""
    start = time.perf_counter()
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        process = subprocess.Popen(command, stdout=out, stderr=err, text=True)
        _, status, usage = os.wait4(process.pid, 0)
        wall = time.perf_counter() - start
        process.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        if process.returncode:
            sys.exit(f"{' '.join(command)}: exit {process.returncode}: {err.read().strip()[-500:]}")
        return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024**2, out.read()


def _write_standard(vtu: Path, path: Path) -> int:
    """The grid of ``vtu`` without its polyhedra (points, standard cells, cell data ``element``); how many cells."""
    import numpy as np
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

    from cospherical.formats.vtu import VTK_CELL, write_grid

    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(vtu))
    reader.Update()
    grid = reader.GetOutput()
    cells = grid.GetCells()
    offsets = vtk_to_numpy(cells.GetOffsetsArray())
    connectivity = vtk_to_numpy(cells.GetConnectivityArray())
    types = vtk_to_numpy(grid.GetCellTypes())
    keep = types != VTK_CELL["polyhedron"]
    sizes = np.diff(offsets)
    write_grid(path, vtk_to_numpy(grid.GetPoints().GetData()), types[keep], connectivity[np.repeat(keep, sizes)],
               np.cumsum(sizes[keep]), cell_data={"element": vtk_to_numpy(grid.GetCellData().GetArray("element"))[keep]})
    return int(keep.sum())


def _stages(command: list[str]) -> str:
    """The command's own stage timings (it prints them on a terminal), made CPU seconds of the process."""
    program = ("import contextlib, sys, time; import cospherical.cli.mesh as m; "
               "m.time.perf_counter = time.process_time; sys.stderr.isatty = lambda: True; "
               "m.stage_bars = lambda bars: contextlib.nullcontext(lambda *a: None); "  # no bars: not a terminal
               "from cospherical.cli import main; sys.argv = sys.argv[1:]; sys.exit(main())")
    result = subprocess.run([sys.executable, "-c", program, *command], capture_output=True, text=True, check=False)
    line = next((x for x in result.stderr.splitlines() if "cospherical mesh: seconds " in x), "")
    return line.partition("cospherical mesh: seconds ")[2] or f"not shown (exit {result.returncode})"


def _write_node(vtu: Path, node: Path) -> None:
    """The VTU's points as a TetGen ``.node`` file (exact: the grid's points are dyadic, 17 digits are exact)."""
    import numpy as np
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(vtu))
    reader.Update()
    points = vtk_to_numpy(reader.GetOutput().GetPoints().GetData()).astype(np.float64)
    with node.open("w") as handle:
        handle.write(f"{len(points)} 3 0 0\n")
        np.savetxt(handle, np.column_stack([np.arange(1, len(points) + 1), points]),
                   fmt=["%d", "%.17g", "%.17g", "%.17g"])


if __name__ == "__main__":
    main()
