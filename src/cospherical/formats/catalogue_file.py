"""The catalogue file: written one element type per line (the catalogue itself is built by
:func:`cospherical.catalogue.build_catalogue`)."""

from __future__ import annotations

from pathlib import Path

# built in the catalogue package; importable from here as before
from ..catalogue.build import build_catalogue, intersection_examples
from ..catalogue.model import Catalogue
from ..files.flowyaml import sequence_line
from ..files.yamlio import atomic_write, yaml_text

__all__ = ["build_catalogue", "intersection_examples", "write_catalogue"]


def write_catalogue(catalogue: Catalogue, path: str | Path) -> None:
    """Write the catalogue as YAML, one element type per line (JSON flow style).

    One line per type keeps the file YAML and its diffs per type, and lets
    :func:`cospherical.catalogue.load_catalogue` read it with a JSON parser:
    every command that names a type reads the catalogue at start-up.
    """
    data = catalogue.to_dict()
    header = {k: v for k, v in data.items() if k != "types"}
    atomic_write(path, yaml_text(header) + "types:\n" + "".join(sequence_line(t) for t in data["types"]))
