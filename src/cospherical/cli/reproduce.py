"""``cospherical reproduce``: the paper's bisection studies, regenerating catalogue/, patterns/ and results/."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..outputs.reproduce import reproduce
from ..studies.reproduce import paper_studies_total
from .progress import progress_bar
from .output import path_argument, say


__all__ = ["DESCRIPTION", "HELP", "add_arguments", "run"]  # what cli/__init__ builds the command from

HELP = "run the paper's bisection studies and regenerate catalogue/, patterns/ and results/"
DESCRIPTION = ("Run the bisection studies of the paper's boxes A (1,1,1), B (1,2,4), C (1,1.4142,1.4142) "
               "and of exact C (1,sqrt 2,sqrt 2), under both point policies, and the octree-leaf studies of A and B; "
               "write the element catalogue, the pattern tables (octree policy and leaves) and a results summary with "
               "the paper side by side.")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--root", type=path_argument, default=Path("."), metavar="DIR",
                        help="where catalogue/, patterns/ and results/ go (default: the current folder)")


def run(args: argparse.Namespace) -> int:
    with progress_bar(paper_studies_total(), "reproduce") as advance:
        message = reproduce(args.root, progress=advance)
    say(message)
    return 0
