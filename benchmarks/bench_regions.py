"""The regions of the global Delaunay mode: Qhull's float proposal (checked in integers) against the exact engine.

    python benchmarks/bench_regions.py [--domain 1 3 9] [--levels 6] [--refine plane:1,1,1,3]

Builds the tree, assembles the leaf mesh and runs its exact Delaunay check once;
then times, in the same process, the whole re-tessellation (``global_delaunay``:
regions, tetrahedra, exact merge into cells) with ``engine="qhull"`` (scipy's
Qhull proposes, integers check, the exact engine only where either fails) and
with ``engine="exact"`` (the incremental Bowyer-Watson in Python integers alone),
and checks that both give the same cells.  Prints CPU seconds (user + system)
and region vertices per CPU-second for each, and their ratio.  The exact engine
is what meshes boxes of extreme aspect ratio (1e-12 x 1 x 3e9), where Qhull's
first simplex is flat in floats.
Writes results/benchmarks/bench_regions.json (benchmarks/record.py).
"""

from __future__ import annotations

import argparse
import resource

import numpy as np

from cospherical.core.configuration import Box
from cospherical.mesh.assembly import assemble
from cospherical.mesh.checks import check_delaunay
from cospherical.mesh.delaunay import global_delaunay
from cospherical.mesh.octree import build_octree, parse_shape
from record import recorded


def cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def cells(mesh) -> set[frozenset[int]]:
    conn, sizes = mesh.connectivity()
    return {frozenset(row[:n].tolist()) for row, n in zip(conn, sizes)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--domain", nargs=3, default=["1", "3", "9"])
    parser.add_argument("--levels", type=int, default=6)
    parser.add_argument("--refine", default="plane:1,1,1,3")
    args = parser.parse_args()
    with recorded(__file__) as record:
        measure(args, record)


def measure(args, record) -> None:
    leaf = assemble(build_octree(Box.parse(args.domain), args.levels, [parse_shape(args.refine)], "vertex"))
    found = check_delaunay(leaf)
    nodes = leaf.element_nodes(found.not_cells)
    region_vertices = len(np.unique(nodes[nodes >= 0]))
    tree = f"{' x '.join(args.domain)}, levels {args.levels}, {args.refine}"
    print(f"domain {tree}: {len(leaf.tree):,} leaves, {len(leaf.vertices):,} vertices; {len(nodes):,} elements "
          f"re-tessellated, {region_vertices:,} region vertices")
    results = {}
    for engine in ("qhull", "exact"):
        start = cpu()
        mesh = global_delaunay(leaf, found, engine=engine)
        seconds = cpu() - start
        results[engine] = (seconds, cells(mesh))
        print(f"  {engine:5s}: {seconds:7.2f} CPU-s, {region_vertices / seconds:9,.0f} region vertices per CPU-s, "
              f"{mesh.cells.clusters} clusters, largest {mesh.cells.largest_cluster:,} vertices")
        record.add(f"{engine} engine, {tree} ({region_vertices:,} region vertices, largest region "
                   f"{mesh.cells.largest_cluster:,})", f"{region_vertices / seconds:,.0f} region vertices per CPU-s")
    assert results["qhull"][1] == results["exact"][1], "the engines disagree"
    ratio = results["exact"][0] / results["qhull"][0]
    print(f"  same cells; exact / qhull CPU: {ratio:.1f}")
    record.add("exact engine / Qhull's checked proposal, CPU", f"{ratio:.1f} (the same cells)")

if __name__ == "__main__":
    main()
