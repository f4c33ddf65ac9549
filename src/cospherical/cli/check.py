"""``cospherical check``: validate catalogue and pattern-table files, deeply, and dual.npz files."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..catalogue import catalogue_path, load_catalogue
from ..formats.check import SharedChecks, check_catalogue, check_patterns, read_document_file
from .output import path_argument, say


__all__ = ["DESCRIPTION", "HELP", "add_arguments", "run"]  # what cli/__init__ builds the command from

HELP = "validate catalogues, pattern tables (YAML or SQLite store) and dual.npz files"
DESCRIPTION = ("Validate catalogues (schema, unique ids, consistent faces, known split types) and pattern "
               "tables (schema, known types, node counts; each element's type, mirror flag and circumcenter recomputed, its node "
               "order giving its type's faces outward, VTK's positive orientation; every configuration's elements tiling the "
               "box, each face met once from each side or once on its boundary), and "
               "dual.npz files of `cospherical mesh --dual` (members, checksums, control volumes summing to the domain, boundary areas to its surface, "
               "and every coefficient, control volume and boundary area computed again from the file's elements and compared exactly, "
               "and the elements proved a mesh of the domain: every face shared by two elements in opposite orientations or in the "
               "domain's boundary). "
               "Exit status 0 when every file is valid, 2 at the first problem.")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("files", nargs="+", type=path_argument, metavar="FILE",
                        help="catalogues, pattern tables (YAML, or the SQLite store of study intersection --patterns) "
                        "and dual.npz files of mesh --dual, checked in order (about 1-2 s per 4096-configuration "
                        "pattern table: every configuration is recomputed, an entry met again in a later file of the "
                        "same box checked once; about 1 s per 20,000-leaf dual.npz: its dual is computed again)")
    parser.add_argument("--catalogue", type=path_argument, metavar="FILE",
                        help="catalogue that pattern tables refer to (default: the shipped one)")
    parser.add_argument("--no-tiling", action="store_true", help="skip the geometric tiling check (faster)")


def run(args: argparse.Namespace) -> int:
    catalogue = None
    shared = SharedChecks()  # what recurs across the tables is checked once (one catalogue for all of them)
    for path in args.files:
        if path.suffix == ".npz":
            _check_dual(path)
            continue
        kind, document = read_document_file(path)
        if kind == "catalogue":
            check_catalogue(document, str(path))
            say(f"{path}: ok, catalogue of {len(document)} element types")
            continue
        if catalogue is None:
            catalogue_file = args.catalogue or catalogue_path()
            catalogue = load_catalogue(catalogue_file)
            check_catalogue(catalogue, str(catalogue_file))
        check_patterns(document, catalogue, str(path), tiling=not args.no_tiling, shared=shared)
        say(f"{path}: ok, pattern table of {len(document.configurations)} configurations")
    return 0


def _check_dual(path: Path) -> None:
    from ..errors import FormatError
    from ..formats.dual import domain_sums, dual_layout, read_dual, verify_dual

    dual = read_dual(path)
    layout = dual_layout(dual, path)  # a device's union of boxes (dual.npz version 4 or 5), else the box
    # version 5: the boundary is the union's; version 4 counted only the bounding box's sides
    whole = dual.regions is not None and dual.regions.interfaces is not None
    volume, expected = domain_sums(layout, whole) if layout is not None else (1, (2, 2, 2))
    total = dual.volume_sum()
    if total != volume:
        raise FormatError(f"{path}: the control volumes sum to {_cut(total)} of the domain's box, not {_cut(volume)}")
    sides = dual.boundary_area_sums()
    if sides != expected:
        raise FormatError(f"{path}: the boundary areas sum to {', '.join(map(_cut, sides))} sides normal to x, y, z, "
                          f"not {', '.join(map(_cut, expected))}")
    verify_dual(dual, path)  # a re-signed change that keeps the sums: every value computed again
    negative = dual.negative_coefficients()
    say(f"{path}: ok, dual of {len(dual.vertices)} vertices and {len(dual.edges)} edges, every value equal to "
          f"its elements' exactly, its elements a mesh of the domain (every face shared by two in opposite "
          f"orientations or in the boundary), control volumes sum to the domain and boundary areas to its surface, "
          f"{negative.interior} interior and {negative.boundary} boundary negative coefficients")


def _cut(value: object, most: int = 40) -> str:
    """An exact sum as an error line names it: its text, cut after ``most`` characters (a forged
    denominator of a thousand digits is named, not echoed)."""
    text = str(value)
    return text if len(text) <= most else text[:most] + "..."
