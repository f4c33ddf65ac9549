"""``cospherical mesh``: mesh a 1-irregular octree from a pattern table, check the mesh exactly, count what occurs."""

from __future__ import annotations

import os
import re
import sys
import time
from pathlib import Path

import numpy as np

from ..catalogue import CRITERIA
from ..core.configuration import Box
from ..core.exact import parse_rational
from ..errors import InputError
from ..files.outputs import OutputFolder
from ..formats.mesh import read_leaves, report_json, table_lookup, write_report
from ..mesh.assembly import assemble
from ..mesh.delaunay import MODES, delaunay_mesh
from ..mesh.octree import BALANCES, BYTES_PER_LEAF, MAX_LEVEL, build_octree, leaf_list_order, leaves_octree, parse_shape
from ..mesh.report import mesh_report
from .progress import stage_bars
from .output import path_argument


__all__ = ["DESCRIPTION", "HELP", "add_arguments", "run"]  # what cli/__init__ builds the command from

HELP = "mesh a 1-irregular octree from a pattern table and check the mesh exactly"
DESCRIPTION = ("Mesh a 1-irregular octree: each leaf's true configuration, its elements from the pattern table "
               "(or tessellated), global vertices; where leaf elements are not globally Delaunay, the exact "
               "Delaunay subdivision of their leaves' vertices (--delaunay global, the default); exact checks "
               "(volume, conformity, circumcenters, global Delaunay), the frequencies of types and "
               "configurations in the mesh and, with --dual, the finite-volume dual (control volumes and "
               "coefficients).")


def add_arguments(parser) -> None:
    parser.add_argument("--domain", nargs=3, metavar=("A", "B", "C"), required=True,
                        help="the root cell's lengths, exact: 1, 1.4142, 3/2, sqrt(2)")
    tree = parser.add_mutually_exclusive_group(required=True)
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
    parser.add_argument("--balance", choices=BALANCES, default="vertex",
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
                        "negative_coefficients and the mixed mesh beside a tetrahedral one in the report")
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
                        help="give up connecting to --scheduler after this long (default 30)")
    parser.add_argument("--dask-workers", type=int, metavar="N",
                        help="run the pieces on a local Dask cluster of N processes (with --partitions)")
    parser.add_argument("--no-delaunay", action="store_true", help="skip the global Delaunay check of the result")
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


def _cut(args, box: Box) -> float:
    """Where the picture cuts: ``--cut``, else through the first shape's centre, else half height."""
    if args.cut is not None:
        value = parse_rational(args.cut, "--cut")
        if not 0 <= value <= 1:
            raise InputError(f"--cut {args.cut}: must be a fraction of the domain height, 0..1")
        if args.out is None or args.partitions is not None:  # no picture is drawn: the option would do nothing
            raise InputError(f"--cut {args.cut}: places mesh.png's cut, which only --out DIR without --partitions "
                             "draws")
        return float(value)
    if args.refine:
        shape = parse_shape(args.refine[0])
        if shape.kind in ("sphere", "point"):
            return min(1.0, max(0.0, float(shape.values[2]) / float(box.c)))
        if shape.kind == "box":
            return min(1.0, max(0.0, float(shape.values[2] + shape.values[5]) / 2 / float(box.c)))
    return 0.5


def _text(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if value is None:
        return "not checked"
    return f"{value:,}" if isinstance(value, int) else str(value)


_OUTPUTS = ("mesh.vtu", "report.json", "mesh.png")


def _writes(name: str) -> bool:
    """Whether a mesh run writes a file of this name: the only files of an earlier run it may remove."""
    from ..mesh.partition import MAX_PARTITIONS

    piece = re.fullmatch(r"mesh-(0|[1-9][0-9]{0,9})\.vtu", name)
    return name in (*_OUTPUTS, "dual.npz", "mesh.pvtu") or piece is not None and int(piece[1]) < MAX_PARTITIONS


def run(args) -> int:
    pieces = _pieces(args)
    if args.out is None:
        return _run(args, None)
    if pieces is not None:
        names = ("mesh.pvtu", "report.json", *(_piece_name(k) for k in range(pieces)))
    else:
        names = _OUTPUTS + (("dual.npz",) if args.dual else ())
    with OutputFolder(args.out, "mesh", names, writes=_writes) as out:  # locked from the start; every file or none
        return _run(args, out)


def _piece_name(k: int) -> str:
    return f"mesh-{k}.vtu"


def _pieces(args) -> int | None:
    """``--partitions`` and its backend, checked before any work; ``None`` without it."""
    from ..mesh.partition import MAX_PARTITIONS
    from ..studies.intersection.backends import MAX_WORKERS, check_backend

    pieces = _count(args.partitions, "--partitions", MAX_PARTITIONS)
    backend = [option for option, value in (("--jobs", args.jobs), ("--scheduler", args.scheduler),
                                            ("--dask-workers", args.dask_workers)) if value is not None]
    if pieces is None:
        if backend:
            raise InputError(f"{backend[0]} runs the pieces of --partitions N: give that too")
        return None
    if args.dual:
        raise InputError("--dual needs the whole mesh in one process: not with --partitions")
    check_backend("cospherical mesh", args.scheduler, args.dask_workers, args.scheduler_timeout)
    args.jobs = _count(args.jobs, "--jobs", MAX_WORKERS) or min(pieces, os.cpu_count() or 1)
    return pieces


def _run(args, out: OutputFolder | None) -> int:
    box = Box.parse(args.domain)
    mode = args.delaunay or ("global" if args.criterion == "optimal" else "leaf")
    if mode == "global" and args.criterion != "optimal":
        raise InputError(f"--delaunay global gives the largest co-spherical cells, which --criterion "
                         f"{args.criterion} splits; use --delaunay leaf with it")
    at = _cut(args, box)  # before the work: a bad --cut is refused at once
    max_leaves = _max_leaves(args.max_leaves)
    clock = time.perf_counter()
    if args.leaves is not None:
        if args.levels is not None:
            raise InputError("--levels goes with --refine, not with --leaves")
        levels, positions = read_leaves(args.leaves, max_leaves)
        tree = leaves_octree(box, levels, positions, where=str(args.leaves))
        described = {"source": "leaves", "file": args.leaves.name, "depth": tree.depth}
        listed = leaf_list_order(levels, positions)  # cell data leaf: the file's numbering
    else:
        shapes = [parse_shape(text) for text in args.refine]
        listed = None  # cell data leaf: the tree's order
        levels = _levels(args.levels)
        tree = build_octree(box, levels, shapes, args.balance, max_leaves)
        described = {"source": "refine", "levels": levels, "refine": [s.text for s in shapes],
                     "balance": args.balance, "depth": tree.depth}
    timings = {"tree": time.perf_counter() - clock}
    clock = time.perf_counter()
    table = lookup = None
    if args.patterns is not None:
        from ..formats.patterns import load

        table = (load(args.patterns), args.criterion, box, str(args.patterns))
        if args.partitions is None:
            lookup = table_lookup(*table)
        timings["table"] = time.perf_counter() - clock
        clock = time.perf_counter()
    if args.partitions is not None:
        return _in_pieces(args, tree, described, table, mode, out, listed)
    large = len(tree) > 50_000  # bars on large trees only (and only on a terminal: tqdm's disable=None)
    bars = {"assembly": (len(tree), "assembling", "leaf"), "regions": (None, "Delaunay check (leaf mesh)", "element"),
            "delaunay": (None, "Delaunay check", "element")}
    with stage_bars(bars) as advance:
        mesh = assemble(tree, lookup, progress=(lambda n: advance("assembly", n)) if large else None,
                        criterion=args.criterion)
        timings["assembly"] = time.perf_counter() - clock
        clock = time.perf_counter()
        bars["regions"] = (len(mesh), "Delaunay check (leaf mesh)", "element")
        mesh, leaf_mesh, checked = delaunay_mesh(mesh, mode,
                                                 progress=(lambda n: advance("regions", n)) if large else None)
        if leaf_mesh is not None:
            timings["global Delaunay"] = time.perf_counter() - clock
            clock = time.perf_counter()
        bars["delaunay"] = (len(mesh), "Delaunay check", "element")  # read when its bar opens
        stages = []

        def stage(name: str) -> None:
            nonlocal clock
            if stages:
                timings[stages[-1]] = time.perf_counter() - clock
            stages.append(name)
            clock = time.perf_counter()

        violating: list = []
        report = mesh_report(mesh, described, args.patterns.name if args.patterns else None, args.criterion,
                             uniform=not args.no_uniform, delaunay=not args.no_delaunay, stage=stage,
                             progress=(lambda n: advance("delaunay", n)) if large else None, violating=violating,
                             leaf_mesh=leaf_mesh, checked=checked)
        dual = None
        if args.dual:
            from ..mesh.dual import dual_summary, mesh_dual

            stage("dual")
            dual = mesh_dual(mesh)
            report.update(dual_summary(dual, len(mesh), report["interior_faces"] + report["boundary_faces"]))
    stage("outputs")
    if out is not None:
        from ..formats.mesh import write_vtu
        from ..outputs.mesh_picture import cut_png

        point_data, cell_data = {}, {}
        if dual is not None:
            from ..formats.dual import write_dual

            write_dual(dual, out.path("dual.npz"))
            point_data = {"control_volume": dual.control_volume, "boundary_area": dual.boundary_area}
            cell_data = {"circumcenter": dual.element_circumcenter}
            if violating:
                ok = np.ones(len(mesh), dtype=np.int8)
                ok[violating[0]] = 0
                cell_data["delaunay_ok"] = ok
        write_vtu(mesh, out.path("mesh.vtu"), point_data=point_data, cell_data=cell_data, leaves=listed)
        shapes = ", ".join(described.get("refine", [])) or described.get("file", "")
        cut_png(mesh, out.path("mesh.png"), at=at,
                title=f"{' x '.join(box.texts)}: {shapes}; {report['leaves']:,} leaves, {report['elements']:,} "
                      f"elements, {report['types']} types (cut at z = {at * float(box.c):.4g})")
        write_report(report, out.path("report.json"))
    timings["outputs"] = time.perf_counter() - clock
    _print(args, report)
    if dual is not None and args.format != "json":
        negative = report["negative_coefficients"]
        sys.stdout.write(f"dual_edges: {report['dual']['edges']:,}\n"
                         f"negative_coefficients: {negative['interior']:,} interior, {negative['boundary']:,} "
                         "boundary\n")
    if sys.stderr.isatty():
        print("cospherical mesh: seconds " + ", ".join(f"{k} {v:.2f}" for k, v in timings.items()), file=sys.stderr)
    return 0


def _print(args, report: dict) -> None:
    if args.format == "json":
        sys.stdout.write(report_json(report))
    else:
        sys.stdout.write("".join(f"{key}: {_text(report[key])}\n" for key in _SUMMARY_KEYS))


def _write_listed_piece(listed: np.ndarray, mesh, path, leaves: np.ndarray) -> None:
    """A piece whose cell data ``leaf`` numbers the leaves as the ``--leaves`` file lists them (tasks pickle it)."""
    from ..formats.mesh import write_piece

    write_piece(mesh, path, listed[leaves])


def _in_pieces(args, tree, described: dict, table: tuple | None, mode: str, out: OutputFolder | None,
               listed: np.ndarray | None) -> int:
    """``--partitions N``: the pieces meshed, checked and written by tasks, mesh.pvtu and the report here."""
    from functools import partial

    from ..formats.mesh import write_piece, write_pvtu
    from ..mesh.partition import mesh_in_pieces

    write = write_piece if listed is None else partial(_write_listed_piece, listed)

    pieces = int(args.partitions)
    paths = [str(out.path(_piece_name(k))) for k in range(pieces)] if out is not None else None
    report = mesh_in_pieces(tree, pieces, (table_lookup, table) if table is not None else None, args.criterion,
                            mode, described, args.patterns.name if args.patterns else None,
                            uniform=not args.no_uniform, delaunay=not args.no_delaunay,
                            write=write if out is not None else None,
                            path=paths.__getitem__ if paths is not None else None, jobs=args.jobs,
                            scheduler=args.scheduler, dask_workers=args.dask_workers)
    if out is not None:
        write_pvtu(out.path("mesh.pvtu"), [Path(p) for p in paths])
        write_report(report, out.path("report.json"))
    _print(args, report)
    return 0
