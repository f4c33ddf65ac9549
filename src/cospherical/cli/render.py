"""``cospherical render``: LaTeX tables (and a PDF) of a study, or of saved study summaries."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

from ..catalogue import build_catalogue, shipped_catalogue
from ..choices import POINT_POLICIES
from ..core.configuration import Box
from ..core.shapes import ELEMENTS
from ..errors import FormatError, InputError, UsageError, one_line
from ..files.yamlio import load_yaml, validate
from ..outputs.latex import render_tables
from ..studies.engine import bisection_codes, run_study
from ..studies.summary import study_summary
from .output import FACE_POINTS_HELP, path_argument, say
from .progress import progress_bar

__all__ = ["DESCRIPTION", "HELP", "add_arguments", "run"]  # what cli/__init__ builds the command from

_SUMMARY_KEYS = ("study", "box", "face_points", "configurations", "fvm_adequate", "fvm_adequate_open", "criteria")


HELP = "write LaTeX tables (and a PDF) of a study"
DESCRIPTION = ("Render the element, frequency, FVM and paper-comparison tables of a study as LaTeX "
               "(jinja2 templates), with a standalone document.tex that includes them all.")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--study", choices=["bisection"], help="run this study first")
    source.add_argument("--summary", nargs="+", type=path_argument, metavar="FILE",
                        help="study summaries written by 'cospherical study --out' or 'reproduce'")
    parser.add_argument("--box", nargs=3, metavar=("A", "B", "C"), help="box of the study (with --study)")
    # None by default so that one given with --summary (where it would do nothing) can be refused
    parser.add_argument("--element", choices=ELEMENTS, default=None,
                        help="base element of the study (with --study; default cuboid)")
    parser.add_argument("--face-points", choices=POINT_POLICIES, default=None,
                        help="with --study: " + FACE_POINTS_HELP)
    parser.add_argument("--out", type=path_argument, required=True, metavar="DIR",
                        help="folder for the .tex files (created; locked for the run; a file an earlier render "
                        "wrote there and this one does not is removed, nothing else)")
    parser.add_argument("--pdf", action="store_true",
                        help="compile document.tex with pdflatex (in a private folder) into DIR/document.pdf")


def _load_summary(path: Path) -> dict[str, Any]:
    """A summary file, validated: every name in it is one of the known ones, every count a number."""
    data: dict[str, Any] = load_yaml(path)  # JSON is YAML; checked below to be a summary
    if isinstance(data, dict) and any(key not in data for key in _SUMMARY_KEYS):
        missing = [k for k in _SUMMARY_KEYS if k not in data]
        raise FormatError(f"{path}: not a study summary (missing {', '.join(missing)})")
    validate(data, "summary", path)
    _refuse_non_finite(data, path)
    try:
        Box.parse(data["box"])
    except InputError as error:
        raise FormatError(f"{path}: box: {error}") from None
    if data["study"] == "intersection" and ("resolution" not in data or "insertion_order" not in data):
        raise FormatError(f"{path}: an intersection study summary needs resolution and insertion_order")
    return data


def _refuse_non_finite(data: object, path: Path) -> None:
    """JSON Schema's numbers admit NaN and infinities (``"share": NaN`` parses); no summary holds one,
    and a table would print ``nan \\%``."""
    stack: list[tuple[tuple[str, ...], object]] = [((), data)]
    while stack:
        where, item = stack.pop()
        if isinstance(item, float) and not math.isfinite(item):
            raise FormatError(f"{path}: at {'.'.join(where) or 'top level'}: {item!r} is not a finite number")
        if isinstance(item, dict):
            stack.extend(((*where, str(k)), v) for k, v in item.items())
        elif isinstance(item, list):
            stack.extend(((*where, str(i)), v) for i, v in enumerate(item))


def run(args: argparse.Namespace) -> int:

    if args.study:
        if not args.box:
            raise UsageError("cospherical render: error: --study needs --box A B C")
        element = args.element or "cuboid"
        codes = bisection_codes(element)
        with progress_bar(len(codes), args.study) as advance:
            study = run_study(args.study, Box.parse(args.box), codes, args.face_points or "octree",
                              progress=advance, element=element)
        catalogue = build_catalogue([study])
        names = catalogue.names()
        summaries = [study_summary(study, names)]
    else:
        given = [flag for flag, value in (("--box", args.box), ("--element", args.element),
                                          ("--face-points", args.face_points)) if value is not None]
        if given:
            raise UsageError(f"cospherical render: error: {given[0]} goes with --study; a summary says its own box, "
                             "element and points")
        summaries = [_load_summary(path) for path in args.summary]
        catalogue = shipped_catalogue()
    written = render_tables(summaries, catalogue, args.out, "Delaunay tessellations of 1-irregular elements",
                            pdf=args.pdf)
    say(f"wrote {len(written)} files in {args.out}")
    if args.pdf:
        say(f"wrote {args.out / 'document.pdf'}")
    elif (args.out / "document.pdf").exists():
        # an earlier render's PDF went with the manifest's leave; one still here is not ours to remove, and
        # it does not show these tables
        print(one_line(f"note: {args.out / 'document.pdf'} was kept: not written by an earlier render or changed "
                       "since; it does not show these tables (--pdf makes one that does)"), file=sys.stderr)
    return 0
