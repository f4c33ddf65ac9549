"""Writing command results: JSON or YAML to stdout; files into an ``--out`` folder held for the run."""

from __future__ import annotations

import argparse
import functools
import sys
from collections.abc import Callable
from pathlib import Path

from ..errors import one_line
from ..files.jsontext import dump, to_json
from ..files.outputs import FolderLock

__all__ = ["FACE_POINTS_HELP", "FORMATS", "dump", "emit", "holding_out", "path_argument", "say", "to_json"]

FORMATS = ("json", "yaml")
FACE_POINTS_HELP = "octree (default): add face and body points of refined neighbours; none: corners and edge points only"


def path_argument(text: str) -> Path:
    """The argparse type of every file and folder option: ``Path("")`` would be the current folder, so
    ``--out ""`` wrote into wherever the command ran; an empty path is refused instead."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path: name a file or folder")
    return Path(text)


def emit(data: object, fmt: str) -> None:
    sys.stdout.write(dump(data, fmt))


def say(line: str) -> None:
    """Write one line of a command's result on stdout as a terminal shows it as written
    (:func:`~cospherical.errors.one_line`).

    A result line names paths and values from outside (a file name may hold a newline
    or an ESC sequence): printed raw, one would forge a line of the result (``x: ok``),
    the other would drive the terminal.
    """
    sys.stdout.write(one_line(line) + "\n")


def holding_out(run: Callable[[argparse.Namespace], int]) -> Callable[[argparse.Namespace], int]:
    """``run(args)`` with ``args.out``, when given, held by a :class:`FolderLock` for the whole run: one
    run at a time fills a folder (a study's checkpoints, a sweep's figures)."""

    @functools.wraps(run)
    def held(args: argparse.Namespace) -> int:
        if args.out is None:
            return run(args)
        with FolderLock(args.out):
            return run(args)

    return held
