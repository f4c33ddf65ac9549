"""The dual of bench_mesh.py's sphere octree, timed; the box method beside discretize's finite volumes.

    python benchmarks/bench_dual.py [--levels 9] [--radius 0.3] [--patterns patterns/leaves-1x1x1.yaml] [--baseline REV]
    python benchmarks/bench_dual.py --files 6,7,8 [--radius 0.3] [--patterns ...]
    python benchmarks/bench_dual.py --poisson [--uniform 2 3 4 5 6] [--graded 4 5 6 7]

Default: the sphere octree of about 1.3 million leaves (level 9), assembled from the
pattern table, then :func:`cospherical.mesh.dual.mesh_dual` on it: wall and CPU
seconds of the assembly and of the dual (the first dual, which also computes each
configuration's pieces, and a second one that finds them remembered), the
Laplacian's assembly, and the process's peak resident memory (after the duals, and
after the Laplacian).  Target: the dual within 10 s CPU on top of the assembly, peak
within 4 GB.  ``--baseline REV`` first runs the same in a process of its own with
``mesh_dual`` as git revision ``REV`` had it (its ``mesh/dual.py``, or its package ``mesh/dual/``), so that
before and after are measured in one run, under one load.

``--files 6,7,8``: per level, the sphere tree's ``dual.npz`` as ``write_dual`` writes it
(every member deflated at zlib's level 1): its bytes and the writer's CPU seconds, beside
the same members deflated at zlib's default level 6 (what the writer did before
2026-12-04: the file's size then, the same zip around them) and both levels' deflating
time, measured in the same process on the same bytes.

``--poisson``: examples/poisson.py's table on larger trees (needs the ``compare``
extra, discretize), with the solve times of both methods.  They write
results/benchmarks/bench_dual.json, bench_dual-files.json or bench_dual-poisson.json
(benchmarks/record.py).
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

from cospherical.mesh.assembly import assemble

ROOT = Path(__file__).resolve().parent.parent


def measure(args) -> dict:
    """The tree, its assembly, the two duals and the Laplacian, timed; printed, and returned for the record."""
    from bench_mesh import sphere_tree, timer

    from cospherical.mesh.dual import mesh_dual

    clock: dict = {}
    stage = timer(clock)
    lookup, tree = sphere_tree(args, stage)
    mesh = stage("assembly", lambda: assemble(tree, lookup))
    dual = stage("dual (first: pieces per configuration)", lambda: mesh_dual(mesh))
    del dual
    dual = stage("dual (pieces remembered)", lambda: mesh_dual(mesh))
    dual_peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2
    stage("laplacian", dual.laplacian)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2
    negative = dual.negative_coefficients()
    # a NegativeCoefficients; a dict from a --baseline revision older than it
    interior, boundary = ((negative["interior"], negative["boundary"]) if isinstance(negative, dict)
                          else (negative.interior, negative.boundary))
    print(f"leaves {len(tree):,}  vertices {len(mesh.vertices):,}  elements {len(mesh):,}  edges {len(dual.edges):,}  "
          f"configurations {len(mesh.tessellations)}  volume sum {dual.volume_sum()}  negative coefficients "
          f"{interior} interior, {boundary} boundary")
    for name, (wall, cpu) in clock.items():
        print(f"{name:42s} {wall:8.2f} s wall {cpu:8.2f} s cpu")
    print(f"peak {dual_peak:.2f} GB after the duals, {peak:.2f} GB after the laplacian", flush=True)
    return {"tree": f"{len(tree):,} leaves, {len(dual.edges):,} edges, {len(mesh.tessellations)} configurations",
            "clock": clock, "dual_peak": dual_peak, "peak": peak}


def baseline(args) -> dict:
    """:func:`measure` in a process of its own, with ``mesh_dual`` as revision ``args.baseline`` had it (its
    ``mesh/dual.py``, or its package ``mesh/dual/``), loaded in place of ours."""
    listed = subprocess.run(["git", "ls-tree", "-r", "--name-only", args.baseline, "src/cospherical/mesh/dual.py",
                             "src/cospherical/mesh/dual"], cwd=ROOT, check=True, capture_output=True,
                            text=True).stdout.split()
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "figures.json"
        for name in listed:
            target = Path(folder) / Path(name).relative_to("src/cospherical/mesh")
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(subprocess.run(["git", "show", f"{args.baseline}:{name}"], cwd=ROOT, check=True,
                                              capture_output=True).stdout)
        module = Path(folder) / ("dual.py" if (Path(folder) / "dual.py").exists() else "dual")
        run = subprocess.run([sys.executable, __file__, "--domain", *args.domain, "--levels", str(args.levels),
                              "--radius", args.radius, "--patterns", args.patterns, "--dual-module", str(module),
                              "--figures", str(out)], capture_output=True, text=True)
        if run.returncode:
            raise SystemExit(f"baseline {args.baseline}: its process failed:\n{run.stderr}")
        print(f"baseline: mesh_dual of {args.baseline}, in a process of its own")
        print(run.stdout, end="")
        return json.loads(out.read_text())


def load_baseline(module: str) -> None:
    """Load a baseline's ``dual.py`` (or ``dual/`` package) as ``cospherical.mesh.dual``, before anything imports
    ours: every caller then uses it."""
    path = Path(module)
    if path.is_dir():
        spec = importlib.util.spec_from_file_location("cospherical.mesh.dual", path / "__init__.py",
                                                      submodule_search_locations=[str(path)])
    else:
        spec = importlib.util.spec_from_file_location("cospherical.mesh.dual", path)
    baseline = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = baseline
    spec.loader.exec_module(baseline)


def big(args, record) -> None:
    before = baseline(args) if args.baseline else None
    if before:
        print("now: mesh_dual of this checkout")
    now = measure(args)
    record.add(f"sphere tree L {args.levels}, R {args.radius}", now["tree"])
    for name, (wall, cpu) in now["clock"].items():
        earlier = f" (before, {args.baseline}: {before['clock'][name][1]:.2f} s CPU)" if before else ""
        record.add(name, f"{cpu:.2f} s CPU, {wall:.2f} s wall{earlier}")
    for key, what in (("dual_peak", "after the duals"), ("peak", "after the Laplacian")):
        earlier = f" (before: {before[key]:.2f} GB)" if before else ""
        record.add(f"peak memory {what}", f"{now[key]:.2f} GB{earlier}")


def files(args, record) -> None:
    """``dual.npz`` per level: as written (zlib level 1) beside its members deflated at level 6 (the writer before)."""
    import time
    import zipfile
    import zlib

    from bench_mesh import sphere_tree, timer

    from cospherical.formats.dual import write_dual
    from cospherical.mesh.dual import mesh_dual

    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for level in [int(x) for x in args.files.split(",")]:
            args.levels = level
            lookup, tree = sphere_tree(args, timer({}))
            dual = mesh_dual(assemble(tree, lookup))
            path = Path(folder) / f"L{level}.npz"
            start = time.process_time()
            write_dual(dual, path)
            write = time.process_time() - start
            deflate = {1: 0.0, 6: 0.0}
            packed = {1: 0, 6: 0}
            with zipfile.ZipFile(path) as archive:
                infos = archive.infolist()
                raw = sum(info.file_size for info in infos)
                headers = path.stat().st_size - sum(info.compress_size for info in infos)  # the zip around them
                for info in infos:
                    blob = archive.read(info)
                    for zlevel in (1, 6):
                        start = time.process_time()
                        compressor = zlib.compressobj(zlevel, zlib.DEFLATED, -15)
                        packed[zlevel] += len(compressor.compress(blob)) + len(compressor.flush())
                        deflate[zlevel] += time.process_time() - start
            # level 1 is what the writer wrote: here one stream a member, there blocks of 1 MiB deflated in threads
            # (formats.deflated: a few bytes a block more)
            assert abs(packed[1] + headers - path.stat().st_size) <= path.stat().st_size // 1000 + 64 * len(infos)
            row = [f"{level}", f"{len(dual.vertices):,}", f"{raw / 1e6:.1f}", f"{(packed[6] + headers) / 1e6:.2f}",
                   f"{path.stat().st_size / 1e6:.2f}", f"{path.stat().st_size / (packed[6] + headers):.2f}",
                   f"{deflate[6]:.2f}", f"{deflate[1]:.2f}", f"{write:.2f}"]
            print(" | ".join(row), flush=True)
            rows.append(row)
            path.unlink()
    record.table(["level", "vertices", "members MB", "dual.npz MB at level 6 (before)", "at level 1 (now)",
                  "size ratio", "deflate s, level 6", "level 1", "write_dual s"], rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from bench_mesh import tree_arguments

    tree_arguments(parser)
    parser.add_argument("--poisson", action="store_true", help="the Poisson comparison instead")
    parser.add_argument("--files", metavar="LEVELS", help="dual.npz's size and writing per level (e.g. 6,7,8) instead")
    parser.add_argument("--baseline", metavar="REV", help="first time the dual of this git revision, the same way")
    parser.add_argument("--dual-module", help=argparse.SUPPRESS)  # a baseline's dual.py or dual/, in its own process
    parser.add_argument("--figures", help=argparse.SUPPRESS)  # where that process leaves its figures
    parser.add_argument("--uniform", type=int, nargs="*", default=[2, 3, 4, 5, 6])
    parser.add_argument("--graded", type=int, nargs="*", default=[4, 5, 6, 7])
    args = parser.parse_args()
    from record import recorded

    if args.dual_module:
        load_baseline(args.dual_module)
        Path(args.figures).write_text(json.dumps(measure(args)))
        return
    if args.files:
        with recorded(__file__, name=f"{Path(__file__).stem}-files") as record:
            files(args, record)
        return
    if not args.poisson:
        with recorded(__file__) as record:
            big(args, record)
        return
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "examples"))
    import poisson

    with recorded(__file__, name=f"{Path(__file__).stem}-poisson") as record:
        rows = poisson.main(["--uniform", *map(str, args.uniform), "--graded", *map(str, args.graded), "--times"])
        record.table(["u", "tree", "L", "method", "unknowns, nonzeros", "max error (order)", "L2 error (order)",
                      "build s", "solve s"],
                     [[row["solution"], row["tree"], row["level"], row["method"],
                       f"{row['unknowns']:,}, {row['nonzeros']:,}", f"{row['max']:.2e} ({row['max_order']})",
                       f"{row['l2']:.2e} ({row['l2_order']})", f"{row['build']:.2f}", f"{row['solve']:.2f}"]
                      for row in rows])


if __name__ == "__main__":
    main()
