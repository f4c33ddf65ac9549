"""Writing command results: JSON or YAML, to stdout."""

from __future__ import annotations

import sys

from ..files.jsontext import dump, to_json

__all__ = ["FACE_POINTS_HELP", "FORMATS", "dump", "emit", "to_json"]

FORMATS = ("json", "yaml")
FACE_POINTS_HELP = "octree (default): add face and body points of refined neighbours; none: corners and edge points only"


def emit(data, fmt: str) -> None:
    sys.stdout.write(dump(data, fmt))
