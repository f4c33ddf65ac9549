"""``cospherical mesh``: mesh a 1-irregular octree from a pattern table, check the mesh exactly, count what occurs."""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..api.mesh import build_mesh, mesh_writes, output_names, piece_name, tree_source
from ..formats.gmsh import GMSH_VERSIONS
from ..choices import BALANCES, CRITERIA, MODES
from ..core.configuration import Box
from ..core.exact import parse_rational
from ..errors import InputError
from ..files.outputs import OutputFolder
from ..formats.mesh import report_json, table_lookup, write_report
from ..mesh.octree import BYTES_PER_LEAF, MAX_LEVEL, parse_shape
from ..mesh.pipeline import TreeSource, delaunay_mode
from .progress import stage_bars
from .output import path_argument

if TYPE_CHECKING:  # the report's types, for annotations only (the report module loads with the mesher)
    from ..mesh.assembly import Mesh
    from ..mesh.report import ChecksSummary, DeviceSummary, MeshReport


__all__ = ["DESCRIPTION", "HELP", "add_arguments", "run"]  # what cli/__init__ builds the command from

HELP = "mesh a 1-irregular octree from a pattern table and check the mesh exactly"
DESCRIPTION = ("Mesh a 1-irregular octree: each leaf's true configuration, its elements from the pattern table "
               "(or tessellated), global vertices; where leaf elements are not globally Delaunay, the exact "
               "Delaunay subdivision of their leaves' vertices (--delaunay global, the default); exact checks "
               "(volume, conformity, circumcenters, global Delaunay), the frequencies of types and "
               "configurations in the mesh and, with --dual, the finite-volume dual (control volumes and "
               "coefficients).")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    domain = parser.add_mutually_exclusive_group(required=True)
    domain.add_argument("--domain", nargs=3, metavar=("A", "B", "C"),
                        help="the root cell's lengths, exact: 1, 1.4142, 3/2, sqrt(2)")
    domain.add_argument("--device", type=path_argument, metavar="FILE",
                        help="a device file (YAML: regions of boxes with their materials, contacts, refinement "
                        "shapes and levels; see the devices page): the tree covers its bounding box, each element "
                        "lies in one region; writes contacts.vtu too, and the dual's parts per region with --dual")
    tree = parser.add_mutually_exclusive_group()
    tree.add_argument("--refine", action="append", metavar="SHAPE",
                      help="split cells whose closed box meets SHAPE, down to --levels: sphere:X,Y,Z,R (its surface), "
                      "plane:NX,NY,NZ,D, point:X,Y,Z or box:X0,Y0,Z0,X1,Y1,Z1, in domain units (repeatable)")
    tree.add_argument("--leaves", type=path_argument, metavar="FILE",
                      help="the leaves as a list of 'level i j k' (text, one per line) or JSON "
                      '{"leaves": [[level, i, j, k], ...]}; checked to tile the domain and be 1-irregular; '
                      "mesh.vtu's cell data leaf is the index in this list")
    parser.add_argument("--levels", metavar="L", help=f"refine down to level L (0..{MAX_LEVEL}); with --refine")
    parser.add_argument("--max-leaves", metavar="N",
                        help="refuse a tree of more leaves than N, estimated before it is built (default: what half "
                        f"of this machine's memory holds at {BYTES_PER_LEAF} bytes a leaf)")
    parser.add_argument("--balance", choices=BALANCES,
                        help="2:1 balance across faces, edges and corners (vertex, default) or faces and edges "
                        "(edge); across faces alone is not offered: it is not 1-irregular")
    parser.add_argument("--patterns", type=path_argument, metavar="FILE",
                        help="pattern table of the domain's box (configurations it lacks are tessellated); "
                        "without it every configuration is tessellated")
    parser.add_argument("--criterion", choices=CRITERIA, default="optimal", help="which elements of the table")
    parser.add_argument("--out", type=path_argument, metavar="DIR",
                        help="write mesh.vtu, report.json and mesh.png here (and dual.npz with --dual)")
    parser.add_argument("--format", choices=("text", "json"), default="text",
                        help="text (default): the main figures; json: the whole report on stdout")
    parser.add_argument("--cut", metavar="Z", help="height of mesh.png's cut as a fraction of the domain height "
                        "(default: through the first shape's centre, else 1/2); with --out, not with --partitions")
    parser.add_argument("--dual", action="store_true",
                        help="the exact finite-volume dual: dual.npz in --out (edges, coefficients, control volumes), "
                        "point data control_volume, boundary_area and cell data circumcenter, delaunay_ok in mesh.vtu, "
                        "negative_coefficients in the report")
    parser.add_argument("--tetrahedral-counts", action="store_true",
                        help="with --dual: the mixed mesh beside a tetrahedral Delaunay mesh of the same vertices "
                        "(TetGen's, else Qhull's: elements, edges, faces, nonzeros) in the report; an outside "
                        "mesher's run, costlier than the dual itself"),
    parser.add_argument("--gmsh", choices=GMSH_VERSIONS, metavar="VERSION",
                        help="also mesh.msh in --out: the mesh split into conforming tetrahedra (no new vertex; the "
                        "exact dual kept, the added edges coupling 0) as a Gmsh file of VERSION 2.2 (DEVSIM's) or "
                        "4.1, each region a named physical volume, each contact and interface (a one-box domain: "
                        "each side xmin..zmax) a named physical surface")
    parser.add_argument("--gmsh-binary", action="store_true", help="mesh.msh in Gmsh's binary form (with --gmsh)")
    parser.add_argument("--tets", action="store_true",
                        help="also tets.vtu in --out: the same tetrahedra, cell data element (the parent) and region")
    parser.add_argument("--delaunay", choices=MODES, default=None,
                        help="global (default with the optimal criterion): the exact Delaunay subdivision of the "
                        "vertices, the leaves whose elements fail the exact check re-tessellated together; leaf "
                        "(default with a split criterion): each leaf's elements from its table")
    parser.add_argument("--partitions", metavar="N",
                        help="mesh the tree in N pieces (runs of the Morton curve: whole subtrees), as separate tasks "
                        "on a local process pool (--jobs) or a Dask cluster; each piece checked exactly, across the "
                        "seams too, and written as DIR/mesh-<k>.vtu with point data global_id, DIR/mesh.pvtu opening "
                        "them as one mesh (no mesh.vtu, mesh.png or --dual)")
    parser.add_argument("--jobs", metavar="N",
                        help="worker processes for --partitions (default: as many as pieces, at most the cores); "
                        "1 meshes the pieces one after another in this process")
    parser.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                        help="run the pieces on this Dask scheduler's workers (with --partitions; --out DIR must be "
                        "a folder the workers share). It must be a scheduler you run: Dask unpickles what it "
                        "sends, so it can run any code as you")
    parser.add_argument("--scheduler-timeout", type=float, default=30.0, metavar="SECONDS",
                        help="give up on a --scheduler host that does not answer after this long (default 30; a port where "
                        "nothing listens, or a host name that does not resolve, is refused at once)")
    parser.add_argument("--dask-workers", type=int, metavar="N",
                        help="run the pieces on a local Dask cluster of N processes (with --partitions)")
    parser.add_argument("--no-delaunay", action="store_true", help="skip the global Delaunay check of the result")
    parser.add_argument("--check", choices=("default", "all"), default="default",
                        help="all: the Delaunay check searches the vertices near every element's sphere with a k-d "
                        "tree, none bounded by the tree's structure (a cross-check of that bound), each table entry used "
                        "is checked under every criterion of the table (not only --criterion's elements; also a "
                        "committed table's, whose entries its bytes' digest proves by default), and the "
                        "uniform study is run even where its figures ship with the package; the report's checks says "
                        "which checks ran and how")
    parser.add_argument("--no-uniform", action="store_true",
                        help="skip the uniform-weight bisection study beside the frequencies")


def _max_leaves(text: str | None) -> int | None:
    if text is None:
        return None
    value = text.strip()
    if not (value.isascii() and value.isdigit() and 0 < len(value) <= 15) or int(value) == 0:
        raise InputError(f"--max-leaves {text!r}: must be a positive integer")
    return int(value)


def _count(text: str | None, option: str, most: int) -> int | None:
    """A count from 1 to ``most`` given as ``option``, or ``None`` when it was not given."""
    if text is None:
        return None
    value = text.strip()
    if not (value.isascii() and value.isdigit() and len(value) <= 15) or not 1 <= int(value) <= most:
        raise InputError(f"{option} {text!r}: must be an integer from 1 to {most:,}")
    return int(value)


def _levels(text: str | None) -> int:
    if text is None:
        raise InputError("--refine needs --levels L")
    value = text.strip()
    if not (value.isascii() and value.isdigit()) or int(value) > MAX_LEVEL:
        raise InputError(f"--levels {text!r}: must be an integer from 0 to {MAX_LEVEL}")
    return int(value)


_SUMMARY_KEYS = ("delaunay_mode", "leaves", "vertices", "elements", "types", "volume_ok", "nonconforming_faces",
                "circumcenters_outside_leaf", "leaves_not_fvm_adequate", "boundary_circumcenters_outside",
                "delaunay_violations", "regions_retessellated", "cells_spanning_leaves",
                "configurations", "configurations_from_table", "configurations_mapped", "tessellated_on_the_fly",
                "paper_final_share")


def _cut(args: argparse.Namespace) -> float | None:
    """``--cut``, checked before the work; ``None``: the picture's own default (through the first shape)."""
    if args.cut is None:
        return None
    value = parse_rational(args.cut, "--cut")
    if not 0 <= value <= 1:
        raise InputError(f"--cut {args.cut}: must be a fraction of the domain height, 0..1")
    if args.out is None or args.partitions is not None:  # no picture is drawn: the option would do nothing
        raise InputError(f"--cut {args.cut}: places mesh.png's cut, which only --out DIR without --partitions "
                         "draws")
    return float(value)


def _text(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if value is None:
        return "not checked"
    return f"{value:,}" if isinstance(value, int) else str(value)


def run(args: argparse.Namespace) -> int:
    pieces = _pieces(args)
    if args.device is not None:
        from ..formats.device_file import read_device

        for option, value in (("--refine", args.refine), ("--leaves", args.leaves), ("--levels", args.levels),
                              ("--balance", args.balance)):
            if value is not None:
                raise InputError(f"{option}: a device file gives its own tree (refine and levels): not with --device")
        if args.partitions is not None:
            raise InputError("--partitions: a device is meshed in one process (each region's Delaunay subdivision, "
                             "its contacts, interfaces and report need the whole region): not with --device")
        args.device = read_device(args.device)  # before the output folder: a bad file writes nothing
    elif args.refine is None and args.leaves is None:
        raise InputError("--domain needs the tree: --refine SHAPE (with --levels L) or --leaves FILE")
    if args.gmsh_binary and args.gmsh is None:
        raise InputError("--gmsh-binary chooses mesh.msh's form: give --gmsh VERSION too")
    if args.tetrahedral_counts and not args.dual:
        raise InputError("--tetrahedral-counts counts beside the dual's figures: give --dual too")
    if (args.gmsh is not None or args.tets) and (args.out is None or pieces is not None):
        option = "--gmsh" if args.gmsh is not None else "--tets"
        raise InputError(f"{option} writes into --out DIR, the whole mesh in one process: with --out, not with "
                         "--partitions")
    if args.out is None:
        return _run(args, None)
    if pieces is not None:
        names = ("mesh.pvtu", "report.json", *(piece_name(k) for k in range(pieces)))
    else:
        names = output_names(args.dual, args.device is not None and args.device.has_faces, args.gmsh is not None,
                             args.tets)
    with OutputFolder(args.out, "mesh", names, writes=mesh_writes) as out:  # locked from the start; every file or none
        return _run(args, out)


def _pieces(args: argparse.Namespace) -> int | None:
    """``--partitions`` and its backend, checked before any work; ``None`` without it."""
    backend = [option for option, value in (("--jobs", args.jobs), ("--scheduler", args.scheduler),
                                            ("--dask-workers", args.dask_workers)) if value is not None]
    if args.partitions is None:
        if backend:
            raise InputError(f"{backend[0]} runs the pieces of --partitions N: give that too")
        return None
    # the partitioned mesher and its backends are imported only for a partitioned run
    from ..execution.backends import MAX_WORKERS, check_backend
    from ..mesh.partition import MAX_PARTITIONS

    pieces = _count(args.partitions, "--partitions", MAX_PARTITIONS)
    assert pieces is not None  # given: a count, or refused
    if args.dual:
        raise InputError("--dual needs the whole mesh in one process: not with --partitions")
    check_backend("cospherical mesh", args.scheduler, args.dask_workers, args.scheduler_timeout)
    args.jobs = _count(args.jobs, "--jobs", MAX_WORKERS) or min(pieces, os.cpu_count() or 1)
    return pieces


def _run(args: argparse.Namespace, out: OutputFolder | None) -> int:
    delaunay_mode(args.criterion, args.delaunay)  # a contradiction refused before the work
    at = _cut(args)
    max_leaves = _max_leaves(args.max_leaves)
    if args.device is not None:
        given = {"device": args.device}
    elif args.leaves is not None:
        if args.levels is not None:
            raise InputError("--levels goes with --refine, not with --leaves")
        if args.balance is not None:  # a leaf list is the tree as given: checked 1-irregular, never balanced
            raise InputError("--balance goes with --refine, not with --leaves")
        given = {"leaves": args.leaves}
    else:
        shapes = [parse_shape(text) for text in args.refine]
        given = {"levels": _levels(args.levels), "refine": shapes, "balance": args.balance or "vertex"}
    box = Box.parse(args.domain) if args.device is None else None
    if args.partitions is not None:
        if box is None:  # refused with its reason before (_pieces): a device is meshed in one process
            raise InputError("--partitions: not with --device")
        return _in_pieces(args, tree_source(box, **given, max_leaves=max_leaves), out)
    with _bars() as progress:
        mesh = build_mesh(box, **given, patterns=args.patterns, criterion=args.criterion, delaunay=args.delaunay,
                          dual=args.dual, tetrahedral_counts=args.tetrahedral_counts, max_leaves=max_leaves,
                          check_delaunay=not args.no_delaunay,
                          uniform=not args.no_uniform, progress=progress, checks=args.check)
        clock = time.perf_counter()
        if out is not None:
            mesh.write_files(out.path, at, args.gmsh, args.gmsh_binary, args.tets, progress=progress)
    timings = {**mesh.report.timings, "outputs": time.perf_counter() - clock}
    report = mesh.report
    _print(args, report)
    if report.dual is not None and report.negative_coefficients is not None and args.format != "json":
        negative = report.negative_coefficients
        sys.stdout.write(f"dual_edges: {report.dual.edges:,}\n"
                         f"negative_coefficients: {negative.interior:,} interior, {negative.boundary:,} "
                         "boundary\n")
    if report.device is not None and args.format != "json":
        _print_device(report.device)
    if sys.stderr.isatty():
        print("cospherical mesh: seconds " + ", ".join(f"{k} {v:.2f}" for k, v in timings.items()), file=sys.stderr)
    return 0


# The bars of the pipeline's long stages: label and unit; drawn on large trees only (and only on a terminal)
_BARS = {"assembly": ("assembling", "leaf"), "regions": ("Delaunay check (leaf mesh)", "element"),
         "delaunay": ("Delaunay check", "element"), "conformity": ("conformity check", "face"),
         "dual": ("finite-volume dual", "dual"), "outputs": ("writing outputs", "file")}
_LARGE_TREE = 50_000
# --partitions: a piece takes seconds on any tree worth cutting, so its bars are drawn whatever the size
_PIECE_BARS = {"pieces": ("meshing pieces", "piece"), "again": ("pieces re-tessellated across seams", "piece")}


@contextmanager
def _bars() -> Iterator[Callable[[str, int | None, int], None]]:
    """Yield the pipeline's ``progress(stage, total, advance)``: a bar per stage once the tree proves large."""
    stages: dict[str, tuple[int | None, str, str]] = {}
    large = False

    with stage_bars(stages) as advance:
        def progress(stage: str, total: int | None, n: int) -> None:
            nonlocal large
            if stage == "assembly" and stage not in stages:
                large = total is not None and total > _LARGE_TREE
            if large:
                stages.setdefault(stage, (total, *_BARS[stage]))  # read when its bar opens
                advance(stage, n)

        yield progress


def _print(args: argparse.Namespace, report: MeshReport) -> None:
    data = report.to_dict()
    if args.format == "json":
        sys.stdout.write(report_json(data))
    else:
        sys.stdout.write("".join(f"{key}: {_text(data[key])}\n" for key in _SUMMARY_KEYS) + _checks_line(report.checks))


def _checks_line(checks: ChecksSummary | None) -> str:
    """The summary's line of the checks that ran (and how the Delaunay check found each sphere's vertices)."""
    if checks is None:
        return ""
    line = "checks: " + ", ".join(checks.run)
    if checks.delaunay_spheres is not None:
        line += (f" (Delaunay: {checks.delaunay_spheres.bounded_by_the_tree:,} spheres bounded by the tree's "
                 "structure, the rest searched)")
    for name, why in (checks.not_run or {}).items():
        line += f"; not run: {name}, {why}"
    return line + "\n"


def _print_device(device: DeviceSummary) -> None:
    """A device's regions and contacts, one line each (names are data: printed as their repr)."""
    lines = [f"resolving_level: {device.resolving_level}, depth: {device.depth}\n"]
    for region in device.regions:
        negative = region.negative_coefficients
        lines.append(f"region {region.name!r} ({region.material!r}): {region.elements:,} elements, "
                     f"{region.nodes:,} nodes, volume {region.volume} ({_text(region.volume_ok)})"
                     + (f", negative coefficients {negative.interior:,} interior" if negative else "") + "\n")
    for contact in device.contacts:
        lines.append(f"contact {contact.name!r} on {contact.region!r}: {contact.faces:,} faces, "
                     f"{contact.nodes:,} nodes, area {contact.area} ({_text(contact.area_ok)})\n")
    for interface in device.interfaces:
        lines.append(f"interface {interface.name!r}: {interface.faces:,} faces, {interface.nodes:,} nodes\n")
    sys.stdout.write("".join(lines))


def _write_listed_piece(listed: np.ndarray, mesh: Mesh, path: str | Path, leaves: np.ndarray) -> None:
    """A piece whose cell data ``leaf`` numbers the leaves as the ``--leaves`` file lists them (tasks pickle it)."""
    from ..formats.mesh import write_piece

    write_piece(mesh, path, listed[leaves])


def _in_pieces(args: argparse.Namespace, source: TreeSource, out: OutputFolder | None) -> int:
    """``--partitions N``: the pieces meshed, checked and written by tasks, mesh.pvtu and the report here."""
    from functools import partial

    from ..formats.mesh import write_piece, write_pvtu
    from ..mesh.partition import mesh_in_pieces

    if args.check == "all":  # every sphere searched (see build_mesh's checks)
        source = replace(source, tree=replace(source.tree, vertex_balanced=False))
    tree, described, listed = source.tree, source.described, source.leaf_order
    mode = delaunay_mode(args.criterion, args.delaunay)
    table = None
    proven = None
    if args.patterns is not None:
        from ..catalogue import shipped_catalogue
        from ..formats.mesh import checked_table, load_table

        # table_lookup's arguments (the shipped catalogue; every criterion checked with --check all; none of a
        # committed table's entries otherwise, as in one process)
        loaded, digest = load_table(args.patterns)
        proven = None if args.check == "all" else checked_table(digest, shipped_catalogue())
        table = (loaded, args.criterion, tree.box, str(args.patterns), None, args.check == "all", proven is None)

    write = write_piece if listed is None else partial(_write_listed_piece, listed)

    pieces = int(args.partitions)
    paths = [str(out.path(piece_name(k))) for k in range(pieces)] if out is not None else None
    stages: dict[str, tuple[int | None, str, str]] = {}
    with stage_bars(stages) as advance:  # a bar per round of pieces, advanced as each piece finishes
        def progress(stage: str, total: int, n: int) -> None:
            stages.setdefault(stage, (total, *_PIECE_BARS[stage]))
            advance(stage, n)

        report = mesh_in_pieces(tree, pieces, (table_lookup, table) if table is not None else None, args.criterion,
                                mode, described, args.patterns.name if args.patterns else None,
                                uniform=not args.no_uniform, delaunay=not args.no_delaunay,
                                write=write if out is not None else None,
                                path=paths.__getitem__ if paths is not None else None, jobs=args.jobs,
                                scheduler=args.scheduler, dask_workers=args.dask_workers, progress=progress)
    if proven is not None and report.checks is not None:
        report = replace(report, checks=report.checks.not_running("table_entries", proven))
    if out is not None and paths is not None:
        write_pvtu(out.path("mesh.pvtu"), [Path(p) for p in paths])
        write_report(report.to_dict(), out.path("report.json"))
    _print(args, report)
    return 0
