import sys

try:
    from .cli import main
except KeyboardInterrupt:  # Ctrl-C while the command starts: as any other interrupt
    print("cospherical: interrupted", file=sys.stderr)
    sys.exit(130)

sys.exit(main())
