"""``cospherical tessellate``: one configuration, its elements as JSON or YAML."""

from __future__ import annotations

import argparse
from collections.abc import Iterable
from pathlib import Path

from ..choices import CRITERIA, POINT_POLICIES, FacePointSource
from ..catalogue import apply_catalogue_criterion
from ..core.configuration import Configuration
from ..core.shapes import ELEMENTS, Shape, standard_shape
from ..core.tessellation import tessellate
from ..errors import FormatError, InputError
from ..files.yamlio import load_yaml
from ..formats.tessellation import tessellation_data
from .output import FACE_POINTS_HELP, FORMATS, emit, path_argument

__all__ = ["DESCRIPTION", "HELP", "add_arguments", "run"]  # what cli/__init__ builds the command from


def _steiner(text: str) -> tuple[str, str]:
    edge, sep, t = text.partition(":")
    if not sep:
        raise argparse.ArgumentTypeError(f"Steiner point {text!r}: write EDGE:T, for example 0:1/2")
    return edge, t


_NUMBERING = """\
node numbering (box A x B x C):
  corners 0-7 (VTK hexahedron order): 0 (0,0,0), 1 (A,0,0), 2 (A,B,0), 3 (0,B,0),
                                      4 (0,0,C), 5 (A,0,C), 6 (A,B,C), 7 (0,B,C)
  edge k joins (0,1) (1,2) (2,3) (3,0) (4,5) (5,6) (6,7) (7,4) (0,4) (1,5) (2,6) (3,7)
    for k = 0..11; its Steiner point is node 8+k, at parameter T from the lower-coordinate end
  face points 20-25 on faces (0,1,5,4) (1,2,6,5) (2,3,7,6) (3,0,4,7) (0,1,2,3) (4,5,6,7);
    body point 26
  circumcenters are in box coordinates (as tess.circumcenter() in Python;
    element.polyhedron.center is the exact value in unit coordinates, [0,1]^3)
"""


HELP = "tessellate one 1-irregular cuboid, prism, pyramid or tetrahedron"
DESCRIPTION = "Tessellate one 1-irregular element: Delaunay cells = largest co-spherical elements."


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.epilog = _NUMBERING  # laid out by hand: printed as written
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    element = parser.add_mutually_exclusive_group()
    element.add_argument("--element", choices=ELEMENTS, default="cuboid",
                         help="the base element in the box (default cuboid): prism (half the box), pyramid (on the "
                         "bottom face, apex at the centre) or tetrahedron (at the corner); node numbering: the documentation's Conventions page")
    element.add_argument("--shape", type=path_argument, metavar="FILE",
                         help="any convex base element: a YAML file with corners (unit coordinates, exact: 0, 1/2), "
                         "edges and faces (corner numbers), checked exactly")
    parser.add_argument("--box", nargs=3, metavar=("A", "B", "C"), required=True,
                        help="edge lengths, exact: 1, 1.4142, 3/2, sqrt(2)")
    points = parser.add_mutually_exclusive_group()
    points.add_argument("--steiner", nargs="+", type=_steiner, default=[], metavar="K:T",
                        help="Steiner point on edge K (0..11 for a cuboid) at parameter T in (0,1), e.g. 0:1/2")
    points.add_argument("--code", help="one hexadecimal digit per edge (12 for a cuboid, 9 prism, 8 pyramid, "
                        "6 tetrahedron), digit k = 16*t on edge k (0 = no point); a cuboid's code may end with the point "
                        "suffix +f<faces>[b]: the faces carrying a point, e.g. 888888888888+f04")
    face_points = parser.add_mutually_exclusive_group()
    face_points.add_argument("--face-points", choices=POINT_POLICIES,
                             help=FACE_POINTS_HELP)
    face_points.add_argument("--faces", nargs="*", metavar="F",
                             help="the faces (0..5 of a cuboid; quadrilaterals of another element) carrying a centre point, given explicitly (no F: none), as at "
                             "an octree leaf whose face neighbours across F are refined")
    parser.add_argument("--body", action="store_true", help="with --faces 0 1 2 3 4 5: the body point (node 26 of a cuboid) too")
    parser.add_argument("--criterion", choices=CRITERIA, default="optimal",
                        help="optimal (default): largest co-spherical elements; internal_faces / "
                        "internal_edges_and_faces: split the types the catalogue does not keep for that criterion")
    parser.add_argument("--format", choices=FORMATS, default="json", help="json (default) or yaml, on stdout")
    parser.add_argument("--vtu", type=path_argument, metavar="FILE", help="also write the tessellation as a VTU mesh (ParaView)")


def _shape_file(path: Path, box: Iterable[str]) -> Shape:
    data = load_yaml(path)
    if not isinstance(data, dict) or any(not isinstance(data.get(key), list) for key in ("corners", "edges", "faces")):
        raise FormatError(f"{path}: needs the lists corners, edges and faces")
    try:
        return Shape.from_vertices(data["corners"], data["edges"], data["faces"], box, str(data.get("name", "element")))
    except InputError as error:
        raise FormatError(f"{path}: {error}") from None


def _configuration(args: argparse.Namespace) -> Configuration:
    """The configuration the arguments name: a cuboid's or another shape's."""
    policy: FacePointSource = args.face_points or "octree"  # no default in the parser: --faces excludes it
    shape = _shape_file(args.shape, args.box) if args.shape else standard_shape(args.element, args.box)
    if args.code is not None:
        return Configuration.from_code(args.code, None, policy, args.faces, args.body, shape=shape)
    return Configuration.from_steiner(None, args.steiner, policy, args.faces, args.body, shape=shape)


def run(args: argparse.Namespace) -> int:
    tess = tessellate(_configuration(args))
    if args.criterion != "optimal":
        tess = apply_catalogue_criterion(tess, args.criterion)
    if args.vtu:
        from ..formats.vtu import write_vtu

        write_vtu(tess, args.vtu)
    data = tessellation_data(tess)
    data["criterion"] = args.criterion
    emit(data, args.format)
    return 0
