"""``cospherical study bisection|leaves|intersection``: every configuration of a family, with statistics."""

from __future__ import annotations

import argparse
import os
import sys
from typing import Any

from ..catalogue import shipped_catalogue
from ..choices import INSERTION_ORDERS, POINT_POLICIES
from ..core.configuration import Box
from ..core.shapes import ELEMENTS
from ..errors import UsageError, one_line
from ..files.yamlio import atomic_write
from ..outputs.report import text_report
from ..paper import paper_comparison, paper_study_key
from ..studies.engine import Study, bisection_codes, run_study
from ..studies.leaves import leaf_codes, run_leaves
from ..studies.summary import compared_with, study_summary
from .output import FACE_POINTS_HELP, dump, emit, holding_out, path_argument
from .progress import progress_bar, stage_bars

__all__ = ["DESCRIPTION", "HELP", "add_arguments", "run"]  # what cli/__init__ builds the command from


_FAMILIES = {
    "bisection": ("a midpoint or nothing on each of the 12 edges: the paper's section 4",
                  "Tessellate all 4096 bisection configurations of a box (a midpoint or nothing on each of the 12 "
                  "edges; 512, 256 or 64 for a prism, pyramid or tetrahedron), one per symmetry orbit, and report "
                  "every element type's frequency, the FVM test and, if asked, the paper's figures beside ours."),
    "leaves": ("the octree-leaf family: the bisection edges with every admissible set of face points",
               "Tessellate the octree-leaf family of a box: every edge mask of the bisection study with every "
               "admissible set of face points and no body point (6210 configurations), as a mesher meets them "
               "at the leaves of a 2:1-balanced octree, and report it beside the octree-policy bisection study."),
    "intersection": ("the paper's section 5: points at multiples of 1/R placed by the midpoint scheme",
                     "Run the paper's intersection study on the cube: Steiner points at multiples of 1/RESOLUTION "
                     "placed by the midpoint scheme (3,375,000 configurations at R = 16), on a process pool or a "
                     "Dask cluster, with checkpoints, and optionally the pattern table of the orbit "
                     "representatives as an indexed SQLite store."),
}


HELP = "run a study over every configuration of a family"
DESCRIPTION = ("Tessellate every configuration of a family (one per symmetry orbit) and report "
               "the frequency of every element type. Each family has its own options: "
               "cospherical study FAMILY --help.")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    families = parser.add_subparsers(dest="family", required=True, metavar="{bisection,leaves,intersection}",
                                     help="the family of configurations to study",
                                     parser_class=type(parser))
    for family, (summary, description) in _FAMILIES.items():
        _add_family(families.add_parser(family, help=summary, description=description), family)


def _add_family(parser: argparse.ArgumentParser, family: str) -> None:
    """The options of one family; the others' are accepted but hidden, so that ``run`` refuses them by name."""

    def option(*flags: str, only: tuple[str, ...] | None = None, **kwargs: Any) -> None:
        if only is not None and family not in only:
            kwargs["help"] = argparse.SUPPRESS
        parser.add_argument(*flags, **kwargs)

    intersection = ("intersection",)
    option("--element", choices=ELEMENTS, default="cuboid", only=("bisection",),
           help="the base element in the box (default cuboid): prism, pyramid or tetrahedron "
           "(512, 256, 64 configurations)")
    option("--box", nargs=3, metavar=("A", "B", "C"), default=["1", "1", "1"], only=("bisection", "leaves"),
           help="edge lengths, exact: 1, 1.4142, 3/2, sqrt(2) (default: the cube)")
    option("--resolution", type=int, only=intersection, help="positions at multiples of 1/R (2, 4, 8, 16; "
           "default 16)")
    option("--order", choices=INSERTION_ORDERS, only=intersection,
           help="the order in which the midpoint scheme inserts the levels (default edge)")
    option("--jobs", type=int, metavar="N", only=intersection,
           help="worker processes (default: all cores, here %d)" % (os.cpu_count() or 1))
    option("--chunk-size", type=int, metavar="N", only=intersection,
           help="orbits per work unit and checkpoint (default 5000)")
    option("--scheduler", metavar="tcp://HOST:PORT", only=intersection,
           help="run the work units on this Dask scheduler's workers. It must be a scheduler you run: Dask "
           "unpickles what it sends, so it can run any code as you")
    option("--scheduler-timeout", type=float, metavar="SECONDS", only=intersection,
           help="give up on a --scheduler host that does not answer after this long (default 30; a port where "
                "nothing listens, or a host name that does not resolve, is refused at once)")
    option("--dask-workers", type=int, metavar="N", only=intersection,
           help="run the work units on a local Dask cluster of N processes")
    option("--no-orbits", action="store_true", only=intersection,
           help="tessellate every configuration, not one per symmetry orbit (a check; the statistics must not "
           "change)")
    option("--resume", action="store_true", only=intersection,
           help="keep finished chunks in DIR/checkpoints and reuse them (needs --out)")
    option("--patterns", action="store_true", only=intersection,
           help="also write the pattern table of the orbit representatives into DIR, as an indexed store "
           "(.sqlite) that a mesher queries one configuration at a time, and as YAML (see --patterns-format); "
           "built from the study's cells: about 1 min at R = 8")
    option("--patterns-format", choices=("auto", "yaml", "store", "both"), only=intersection,
           help="the pattern table as yaml, store or both (default auto: both while the YAML stays small "
           "enough to read, up to R = 4; the store alone above, where it is over a GB)")
    option("--face-points", choices=POINT_POLICIES, default="octree", only=("bisection",), help=FACE_POINTS_HELP)
    option("--out", type=path_argument, metavar="DIR",
           help="also write the summary (JSON) and the pattern table into DIR")
    option("--format", choices=("text", "json"), default="text",
           help="text (default): the frequency table; json: the summary as data")
    option("--compare-paper", action="store_true", only=("bisection", "intersection"),
           help="print the paper's figures beside ours, each difference marked and explained")


# Options of the intersection study only: given to the bisection study they are refused, not ignored.
_INTERSECTION_ONLY = ("resolution", "order", "jobs", "chunk_size", "scheduler", "scheduler_timeout", "dask_workers",
                     "no_orbits", "resume", "patterns", "patterns_format")
_INTERSECTION_DEFAULTS = {"resolution": 16, "order": "edge", "jobs": os.cpu_count() or 1, "chunk_size": 5000,
                         "scheduler_timeout": 30.0}


@holding_out
def run(args: argparse.Namespace) -> int:
    if args.element != "cuboid" and args.family != "bisection":
        raise UsageError(f"cospherical study: error: --element {args.element}: the {args.family} study is of cuboids; "
                         "other base elements have the bisection study")
    if args.family == "intersection":
        for name, value in _INTERSECTION_DEFAULTS.items():
            if getattr(args, name) is None:
                setattr(args, name, value)
        return _intersection(args)
    given = [name for name in _INTERSECTION_ONLY if getattr(args, name) not in (None, False)]  # bisection, leaves
    if given:
        option = "--" + given[0].replace("_", "-")
        raise UsageError(f"cospherical study: error: {option} is an option of the intersection study only")
    box = Box.parse(args.box)
    codes = bisection_codes(args.element)
    if args.family == "leaves":
        if args.face_points != "octree" or args.compare_paper:
            raise UsageError("cospherical study: error: the leaf study gives its face points in its codes and sets "
                             "the octree-policy bisection study beside it: no --face-points, no --compare-paper")
        with progress_bar(len(leaf_codes()) + len(codes), "leaves") as advance:
            bisection = run_study("bisection", box, codes, "octree", progress=advance)
            study = run_leaves(box, progress=advance, known=[bisection])  # its tessellations where the points agree
        summary = compared_with(study_summary(study), study_summary(bisection))
    else:
        with progress_bar(len(codes), "bisection") as advance:
            study = run_study("bisection", box, codes, args.face_points, progress=advance, element=args.element)
        summary = study_summary(study)
    if args.out:
        from ..formats.patterns import pattern_name, write_patterns  # loads numpy: only when a table is written

        stem = pattern_name(study.name, box.texts, study.face_points, study.element)
        atomic_write(args.out / f"{stem}.json", dump(summary, "json"))
        write_patterns(study, args.out / f"{stem}.yaml", shipped_catalogue().version)
    return _report(summary, args, study)


def _report(summary: dict[str, Any], args: argparse.Namespace, study: Study | None = None) -> int:
    """The summary on stdout, as JSON or text, with the paper beside it if asked."""
    if args.format == "json":
        if args.compare_paper:
            key, _ = paper_study_key(summary)
            summary["paper"] = paper_comparison(summary, key) if key else None
        emit(summary, "json")
    else:
        print(text_report(summary, compare_paper=args.compare_paper, study=study), end="")
    return 0


def _intersection(args: argparse.Namespace) -> int:
    from ..studies.intersection import run_intersection, set_patterns  # numpy: not for the other studies
    from ..execution.backends import check_backend

    if any(side != 1 for side in Box.parse(args.box).squared) or args.face_points != "octree":
        raise UsageError("cospherical study: error: the intersection study is the paper's: the cube, octree points")
    if args.resolution not in (2, 4, 8, 16):
        raise UsageError(f"cospherical study: error: --resolution {args.resolution}: choose 2, 4, 8 or 16")
    if args.patterns and not args.out:
        raise UsageError("cospherical study: error: --patterns writes into --out DIR")
    if args.patterns_format is not None and not args.patterns:
        raise UsageError("cospherical study: error: --patterns-format is the form of the --patterns table")
    if args.resume and not args.out:
        raise UsageError("cospherical study: error: --resume keeps its checkpoints in --out DIR")
    check_backend("cospherical study", args.scheduler, args.dask_workers, args.scheduler_timeout, args.jobs)
    checkpoints = args.out / "checkpoints" if args.out else None
    total = len(set_patterns(args.resolution, args.order)) ** 3  # one pattern per set of parallel edges
    with stage_bars({"cells": (total, f"intersection 1/{args.resolution}: cells", "cfg"),
                     "elements": (None, "distinct elements classified and split", "el")}) as advance:
        summary = run_intersection(args.resolution, args.order, jobs=args.jobs,
                                   checkpoints=checkpoints if args.resume else None, progress=advance,
                                   chunk=max(1, args.chunk_size), scheduler=args.scheduler,
                                   dask_workers=args.dask_workers, brute_force=args.no_orbits,
                                   notice=lambda line: print(one_line(f"cospherical study: note: {line}"), file=sys.stderr))
    if args.out:
        stem = f"intersection-r{args.resolution}-{args.order}"
        atomic_write(args.out / f"{stem}.json", dump(summary, "json"))
        atomic_write(args.out / f"{stem}.yaml", dump(summary, "yaml"))
        from ..outputs.latex import render_tables  # jinja2: loaded only when tables are written

        render_tables([summary], shipped_catalogue(), args.out / "latex",
                      f"Intersection study at 1/{args.resolution}, insertion order {args.order}")
        if args.patterns:
            from ..formats.intersection_table import YAML_UP_TO, write_pattern_table
            from ..studies.intersection.table import TableRun

            form = args.patterns_format or "auto"
            if form == "auto":
                form = "both" if args.resolution <= YAML_UP_TO else "store"
            elif form != "store" and args.resolution > YAML_UP_TO:
                print(f"cospherical study: note: the YAML of a table at R = {args.resolution} is over a GB, more than "
                      "load_patterns and check read (512 MB); they read the store (--patterns-format store)",
                      file=sys.stderr)
            with stage_bars({"cells": (summary["orbits"], "pattern table: cells", "cfg"),
                             "elements": (None, "distinct cells written", "el"),
                             "entries": (summary["orbits"], "pattern table: entries", "cfg")}) as advance:
                run = TableRun(summary, jobs=args.jobs, progress=advance, scheduler=args.scheduler,
                               dask_workers=args.dask_workers)
                write_pattern_table(run, shipped_catalogue().version,
                                    yaml_path=args.out / f"{stem}-patterns.yaml" if form != "store" else None,
                                    store=args.out / f"{stem}-patterns.sqlite" if form != "yaml" else None)
    return _report(summary, args)
