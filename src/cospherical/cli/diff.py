"""``cospherical diff``: what changed between two catalogue or pattern-table versions.

Exit status as diff(1): 0 no difference, 1 differences, 2 trouble.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import UsageError
from ..files.git import git_text
from ..formats.check import document_data, read_document, read_document_file
from ..formats.diff import diff_documents, has_changes, text_report
from .output import dump


__all__ = ["DESCRIPTION", "HELP", "add_arguments", "run"]  # what cli/__init__ builds the command from

HELP = "compare two catalogue or pattern-table versions"
DESCRIPTION = ("Compare two catalogues (types matched by canonical code) or two pattern tables "
               "(configurations whose elements changed, per criterion). Exit status: 0 no difference, "
               "1 differences, 2 trouble.")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("files", nargs="+", metavar="FILE", help="OLD NEW, or with --rev just the file")
    parser.add_argument("--rev", metavar="REV", help="read OLD from git at this revision (e.g. HEAD~3)")
    parser.add_argument("--format", choices=("text", "json", "yaml"), default="text",
                        help="text (default): a readable report; json or yaml: the same report as data")


def _from_git(rev: str, path: Path) -> str:
    # A revision is data, never an option: refuse a leading '-' and end git's options before it.
    if not rev or rev.startswith("-") or any(ch.isspace() or ch == ":" or not ch.isprintable() for ch in rev):
        raise UsageError(f"cospherical diff: error: --rev {rev!r}: not a git revision")
    return git_text(rev, path)


def run(args: argparse.Namespace) -> int:

    if args.rev:
        if len(args.files) != 1:
            raise UsageError("cospherical diff: error: with --rev give one FILE (OLD is that file at REV)")
        new_path = Path(args.files[0])
        old_name, new_name = f"{new_path}@{args.rev}", str(new_path)
        old = document_data(read_document(_from_git(args.rev, new_path), old_name)[1])
    else:
        if len(args.files) != 2:
            raise UsageError("cospherical diff: error: give OLD NEW (or --rev REV FILE)")
        old_name, new_name = args.files
        old = document_data(read_document_file(old_name)[1])
        new_path = Path(new_name)
    new = document_data(read_document_file(new_path)[1])
    report = diff_documents(old, new, old_name, new_name)
    if args.format == "text":
        sys.stdout.write(text_report(report, old_name, new_name))
    else:
        sys.stdout.write(dump({"old": old_name, "new": new_name, **report}, args.format))
    return 1 if has_changes(report) else 0
