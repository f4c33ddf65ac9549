"""``python -m cospherical``: the command line (:func:`cospherical.cli.main`)."""

import sys

__all__: list[str] = []  # a script: nothing to import from it

try:
    from .cli import main
except KeyboardInterrupt:  # Ctrl-C while the command starts: as any other interrupt
    print("cospherical: interrupted", file=sys.stderr)
    sys.exit(130)

sys.exit(main())
