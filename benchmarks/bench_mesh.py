"""Mesh a sphere octree of about a million leaves from a pattern table, with every exact check, timed.

    python benchmarks/bench_mesh.py [--levels 9] [--radius 0.3] [--patterns patterns/leaves-1x1x1.yaml]
    python benchmarks/bench_mesh.py --domain 1 2 4 --levels 8 --radius 0.6 --patterns patterns/leaves-1x2x4.yaml

The sphere is centred in the domain.
Stages, each timed on its own: loading the table; building the octree (refinement
and vertex balance); assembly (each leaf's configuration from the vertex set,
elements from the table, global vertex ids; the distinct configurations are looked
up and measured once each, shown separately as "configurations"); the volume,
conformity and circumcenter checks; the exact global Delaunay check; the
frequency statistics (without the uniform study).  Then the global mode
(``--delaunay global``): the exact Delaunay subdivision from the leaf mesh and its
check (the regions re-tessellated), and the same checks and statistics on it.
Leaf mode = assembly + checks + statistics; global mode = the same assembly +
the leaf mesh's Delaunay check + re-tessellation + checks + statistics of the
result; their ratio is printed (target: at most 3).  Peak memory is the process's
maximum resident set size.  Targets: assembly >= 100,000 leaves/s,
volume + conformity + circumcenters < 2 min, Delaunay < 5 min, peak < 4 GB.
Writes results/benchmarks/bench_mesh.json (benchmarks/record.py).
"""

from __future__ import annotations

import argparse
import resource
import time

from cospherical import load_patterns
from cospherical.core.configuration import Box
from cospherical.formats.mesh import table_lookup
from cospherical.mesh.assembly import assemble
from cospherical.mesh.checks import check_circumcenters, check_conformity, check_delaunay, check_volume
from cospherical.mesh.delaunay import global_delaunay
from cospherical.mesh.octree import build_octree, parse_shape
from cospherical.mesh.statistics import mesh_statistics
from record import recorded


def tree_arguments(parser: argparse.ArgumentParser) -> None:
    """The sphere tree's options (also bench_dual.py's)."""
    parser.add_argument("--domain", nargs=3, default=["1", "1", "1"])
    parser.add_argument("--levels", type=int, default=9)
    parser.add_argument("--radius", default="0.3")
    parser.add_argument("--patterns", default="patterns/leaves-1x1x1.yaml")


def timer(clock: dict):
    """``stage(name, function)``: run it, record (wall, CPU) seconds in ``clock[name]``, return its value."""
    def stage(name, function):
        start, cpu = time.perf_counter(), time.process_time()
        value = function()
        clock[name] = (time.perf_counter() - start, time.process_time() - cpu)
        return value

    return stage


def sphere_tree(args, stage):
    """The table's lookup and the sphere octree centred in the domain, each timed."""
    box = Box.parse(args.domain)
    center = ",".join(str(float(length) / 2) for length in box.lengths)
    table = stage("load table", lambda: load_patterns(args.patterns))
    lookup = table_lookup(table, "optimal", box, args.patterns)
    tree = stage("octree", lambda: build_octree(box, args.levels, [parse_shape(f"sphere:{center},{args.radius}")]))
    return lookup, tree


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    tree_arguments(parser)
    args = parser.parse_args()
    with recorded(__file__) as record:
        measure(args, record)


def measure(args, record) -> None:
    clock: dict = {}
    stage = timer(clock)
    lookup, tree = sphere_tree(args, stage)
    cache: dict = {}
    stage("configurations (first assembly)", lambda: assemble(tree, lookup, cache=cache))
    mesh = stage("assembly", lambda: assemble(tree, lookup, cache=cache))
    volume = stage("volume", lambda: check_volume(mesh))
    conformity = stage("conformity", lambda: check_conformity(mesh))
    centers = stage("circumcenters", lambda: check_circumcenters(mesh))
    delaunay = stage("delaunay", lambda: check_delaunay(mesh))
    stage("statistics", lambda: mesh_statistics(mesh))
    whole = stage("global: re-tessellation", lambda: global_delaunay(mesh, delaunay))
    found = {}
    for name, check in (("volume", check_volume), ("conformity", check_conformity),
                        ("circumcenters", check_circumcenters), ("delaunay", check_delaunay)):
        result = stage(f"global: {name}", lambda: check(whole))
        found.update(result.figures())
    stage("global: statistics", lambda: mesh_statistics(whole))
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2
    print(f"leaves {len(tree):,}  vertices {len(mesh.vertices):,}  elements {len(mesh):,}  "
          f"configurations {len(mesh.tessellations)}  on the fly {sum(p.on_the_fly for p in mesh.tessellations)}")
    for name, (wall, cpu) in clock.items():
        print(f"{name:34s} {wall:8.2f} s wall {cpu:8.2f} s cpu")
    wall = clock["assembly"][0]
    print(f"assembly rate {len(tree) / wall:,.0f} leaves/s (wall)")
    checks = sum(clock[k][0] for k in ("volume", "conformity", "circumcenters"))
    print(f"volume + conformity + circumcenters {checks:.1f} s; delaunay {clock['delaunay'][0]:.1f} s; "
          f"peak {peak:.2f} GB")
    print({**volume.figures(), **conformity.figures(), **centers.figures(), **delaunay.figures()})
    leaf_stages = ("assembly", "volume", "conformity", "circumcenters", "delaunay", "statistics")
    global_stages = ("assembly", "delaunay", *(name for name in clock if name.startswith("global: ")))
    leaf_mode, global_mode = (sum(clock[k][0] for k in stages) for stages in (leaf_stages, global_stages))
    leaf_cpu, global_cpu = (sum(clock[k][1] for k in stages) for stages in (leaf_stages, global_stages))
    cells = whole.cells
    print(f"global: {len(whole):,} elements, {len(cells) if cells else 0:,} cells in "
          f"{cells.clusters if cells else 0} clusters (largest {cells.largest_cluster if cells else 0:,} vertices), "
          f"{int(cells.spanning.sum()) if cells else 0:,} spanning leaves")
    print({k: v for k, v in found.items() if not k.startswith("_") and k != "nonconforming_examples"})
    print(f"leaf mode {leaf_mode:.1f} s wall, {leaf_cpu:.1f} s cpu; global mode {global_mode:.1f} s wall, "
          f"{global_cpu:.1f} s cpu: {global_mode / leaf_mode:.2f}x wall, {global_cpu / leaf_cpu:.2f}x cpu")
    record.add(f"sphere tree {' x '.join(args.domain)}, L {args.levels}, R {args.radius}",
               f"{len(tree):,} leaves, {len(mesh.vertices):,} vertices, {len(mesh):,} elements, "
               f"{len(mesh.tessellations)} configurations")
    for name, (wall, cpu) in clock.items():
        record.add(name, f"{cpu:.2f} s CPU, {wall:.2f} s wall")
    record.add("leaf mode (assembly, checks, statistics) vs global mode", f"{leaf_cpu:.1f} s vs {global_cpu:.1f} s CPU: "
               f"{global_cpu / leaf_cpu:.2f}x CPU, {global_mode / leaf_mode:.2f}x wall")
    record.add("global mode's result", f"{len(whole):,} cells, {cells.clusters if cells else 0} clusters, "
               f"{found.get('delaunay_violations')} Delaunay violations, {found.get('delaunay_ties')} ties")
    record.add("peak memory (the process)", f"{peak:.2f} GB")


if __name__ == "__main__":
    main()
