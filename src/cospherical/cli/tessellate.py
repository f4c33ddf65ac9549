"""``cospherical tessellate``: one configuration, its elements as JSON or YAML."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..catalogue import CRITERIA, apply_catalogue_criterion
from ..core.configuration import POINT_POLICIES, Configuration
from ..core.tessellation import tessellate
from ..errors import InputError
from ..formats.tessellation import tessellation_data
from .output import FORMATS, emit


def _steiner(text: str) -> tuple[str, str]:
    edge, sep, t = text.partition(":")
    if not sep:
        raise argparse.ArgumentTypeError(f"Steiner point {text!r}: write EDGE:T, for example 0:1/2")
    return edge, t


def add_parser(commands) -> None:
    parser = commands.add_parser(
        "tessellate",
        help="tessellate one 1-irregular cuboid",
        description="Tessellate one 1-irregular cuboid: Delaunay cells = largest co-spherical elements.",
    )
    parser.add_argument("--box", nargs=3, metavar=("A", "B", "C"), required=True,
                        help="edge lengths, exact: 1, 1.4142, 3/2, sqrt(2)")
    points = parser.add_mutually_exclusive_group()
    points.add_argument("--steiner", nargs="+", type=_steiner, default=[], metavar="K:T",
                        help="Steiner point on edge K (0..11) at parameter T in (0,1), e.g. 0:1/2")
    points.add_argument("--code", help="12 hexadecimal digits, digit k = 16*t on edge k (0 = no point), optionally "
                        "followed by the point suffix +f<faces>[b]: the faces carrying a point, e.g. 888888888888+f04")
    face_points = parser.add_mutually_exclusive_group()
    face_points.add_argument("--face-points", choices=POINT_POLICIES,
                             help="octree (default): add face and body points of refined neighbours; none: edges only")
    face_points.add_argument("--faces", nargs="*", metavar="F",
                             help="the faces (0..5) carrying a centre point, given explicitly (no F: none), as at "
                             "an octree leaf whose face neighbours across F are refined")
    parser.add_argument("--body", action="store_true", help="with --faces 0 1 2 3 4 5: the body point (node 26) too")
    parser.add_argument("--criterion", choices=CRITERIA, default="optimal",
                        help="optimal (default): largest co-spherical elements; internal_faces / "
                        "internal_edges_and_faces: split the types the catalogue does not keep for that criterion")
    parser.add_argument("--format", choices=FORMATS, default="json")
    parser.add_argument("--vtu", type=Path, metavar="FILE", help="also write the tessellation as a VTU mesh (ParaView)")
    parser.set_defaults(run=run)


def run(args) -> int:
    policy = args.face_points or "octree"  # no default in the parser: --faces excludes it
    if args.code is not None:
        configuration = Configuration.from_code(args.code, args.box, policy, args.faces, args.body)
    else:
        steiner = {}
        for edge, t in args.steiner:
            if edge.strip() in steiner:
                raise InputError(f"edge {edge}: given twice")
            steiner[edge.strip()] = t
        configuration = Configuration.from_steiner(args.box, steiner, policy, args.faces, args.body)
    tess = tessellate(configuration)
    if args.criterion != "optimal":
        tess = apply_catalogue_criterion(tess, args.criterion)
    if args.vtu:
        from ..formats.vtu import write_vtu

        write_vtu(tess, args.vtu)
    data = tessellation_data(tess)
    data["criterion"] = args.criterion
    emit(data, args.format)
    return 0
