"""``cospherical study bisection``: every bisection configuration of a box, with statistics."""

from __future__ import annotations

from pathlib import Path

from ..catalogue import shipped_catalogue
from ..configuration import POINT_POLICIES, Box
from ..patterns import pattern_name, write_patterns
from ..report import study_summary, text_report
from ..study import bisection_codes, run_study
from ..yamlio import atomic_write
from .output import dump, emit
from .progress import progress_bar


def add_parser(commands) -> None:
    parser = commands.add_parser(
        "study",
        help="run a study over every configuration of a family",
        description="Tessellate every configuration of a family (one per symmetry orbit) and report "
        "the frequency of every element type.",
    )
    parser.add_argument("family", choices=["bisection"], help="bisection: a midpoint or nothing on each of the 12 edges")
    parser.add_argument("--box", nargs=3, metavar=("A", "B", "C"), required=True,
                        help="edge lengths, exact: 1, 1.4142, 3/2, sqrt(2)")
    parser.add_argument("--face-points", choices=POINT_POLICIES, default="octree")
    parser.add_argument("--out", type=Path, metavar="DIR",
                        help="also write the summary (JSON) and the pattern table (YAML) into DIR")
    parser.add_argument("--format", choices=("text", "json"), default="text")
    parser.add_argument("--compare-paper", action="store_true",
                        help="print the paper's figures beside ours, each difference marked and explained")
    parser.set_defaults(run=run)


def run(args) -> int:
    box = Box.parse(args.box)
    codes = bisection_codes()
    with progress_bar(len(codes), "bisection") as advance:
        study = run_study("bisection", box, codes, args.face_points, progress=advance)
    summary = study_summary(study)
    if args.out:
        stem = pattern_name("bisection", box.texts, args.face_points)
        atomic_write(args.out / f"{stem}.json", dump(summary, "json"))
        write_patterns(study, args.out / f"{stem}.yaml", shipped_catalogue()["version"])
    if args.format == "json":
        if args.compare_paper:
            from ..report import paper_comparison, paper_study_key

            key, notes = paper_study_key(summary)
            summary["paper"] = paper_comparison(summary, key) if key else None
        emit(summary, "json")
    else:
        print(text_report(summary, compare_paper=args.compare_paper, study=study), end="")
    return 0
