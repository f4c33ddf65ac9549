"""The dual of bench_mesh.py's sphere octree, timed; the box method beside discretize's finite volumes.

    python benchmarks/bench_dual.py [--levels 9] [--radius 0.3] [--patterns patterns/leaves-1x1x1.yaml]
    python benchmarks/bench_dual.py --poisson [--uniform 2 3 4 5 6] [--graded 4 5 6 7]

Default: the sphere octree of about 1.3 million leaves (level 9), assembled from the
pattern table, then :func:`cospherical.mesh.dual.mesh_dual` on it: wall and CPU
seconds of the assembly and of the dual (the first dual, which also computes each
configuration's pieces, and a second one that finds them remembered), the
Laplacian's assembly, and the process's peak resident memory.  Target: the dual
within 10 s CPU on top of the assembly, peak within 4 GB.

``--poisson``: examples/poisson.py's table on larger trees (needs the ``compare``
extra, discretize), with the solve times of both methods.  Both write
results/benchmarks/bench_dual.json or bench_dual-poisson.json (benchmarks/record.py).
"""

from __future__ import annotations

import argparse
import resource
import sys
import time
from pathlib import Path

from cospherical.mesh.assembly import assemble
from cospherical.mesh.dual import mesh_dual


def big(args, record) -> None:
    from bench_mesh import sphere_tree, timer

    clock: dict = {}
    stage = timer(clock)
    lookup, tree = sphere_tree(args, stage)
    mesh = stage("assembly", lambda: assemble(tree, lookup))
    dual = stage("dual (first: pieces per configuration)", lambda: mesh_dual(mesh))
    del dual
    dual = stage("dual (pieces remembered)", lambda: mesh_dual(mesh))
    stage("laplacian", dual.laplacian)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2
    negative = dual.negative_coefficients()
    print(f"leaves {len(tree):,}  vertices {len(mesh.vertices):,}  elements {len(mesh):,}  edges {len(dual.edges):,}  "
          f"configurations {len(mesh.patterns)}  volume sum {dual.volume_sum()}  negative coefficients "
          f"{negative['interior']} interior, {negative['boundary']} boundary")
    for name, (wall, cpu) in clock.items():
        print(f"{name:42s} {wall:8.2f} s wall {cpu:8.2f} s cpu")
    print(f"peak {peak:.2f} GB")
    record.add(f"sphere tree L {args.levels}, R {args.radius}", f"{len(tree):,} leaves, {len(dual.edges):,} edges, "
               f"{len(mesh.patterns)} configurations")
    for name, (wall, cpu) in clock.items():
        record.add(name, f"{cpu:.2f} s CPU, {wall:.2f} s wall")
    record.add("peak memory (the process)", f"{peak:.2f} GB")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from bench_mesh import tree_arguments

    tree_arguments(parser)
    parser.add_argument("--poisson", action="store_true", help="the Poisson comparison instead")
    parser.add_argument("--uniform", type=int, nargs="*", default=[2, 3, 4, 5, 6])
    parser.add_argument("--graded", type=int, nargs="*", default=[4, 5, 6, 7])
    args = parser.parse_args()
    from record import recorded

    if not args.poisson:
        with recorded(__file__) as record:
            big(args, record)
        return
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "examples"))
    import poisson

    with recorded(f"{Path(__file__).stem}-poisson.py"):  # the table is the script's output, kept whole
        poisson.main(["--uniform", *map(str, args.uniform), "--graded", *map(str, args.graded), "--times"])


if __name__ == "__main__":
    main()
