"""The ``cospherical`` command: a thin layer, one module per subcommand."""

from __future__ import annotations

import argparse
import sys

from ..exact import InputError
from . import diff, render, reproduce, study, tessellate

__all__ = ["main"]

SUBCOMMANDS = (tessellate, study, reproduce, render, diff)


class UsageError(Exception):
    """A command-line usage error (exit code 2)."""


class _Parser(argparse.ArgumentParser):
    # argparse prints the whole usage block; a usage error here is one line.
    def error(self, message: str):
        raise UsageError(f"{self.prog}: error: {message}")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="cospherical",
        description="Delaunay tessellations of 1-irregular cuboids with co-spherical elements.",
    )
    from .. import __version__

    parser.add_argument("--version", action="version", version=f"cospherical {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for module in SUBCOMMANDS:
        module.add_parser(commands)
    return parser


def main(argv: list[str] | None = None) -> int:
    try:
        args = build_parser().parse_args(argv)
        return args.run(args)
    except (UsageError, InputError) as error:
        print(f"cospherical: error: {error}" if isinstance(error, InputError) else error, file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("cospherical: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
