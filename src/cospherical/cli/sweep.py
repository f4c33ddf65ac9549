"""``cospherical sweep``: the bisection study over a grid of boxes, or exactly along a ray."""

from __future__ import annotations

import argparse
import os

from ..core.exact import parse_rational
from ..errors import InputError
from ..files.yamlio import atomic_write
from ..outputs.figures import heatmap_png, heatmap_tex, steps_png, steps_tex
from ..outputs.latex import environment
from ..studies.ray import Ray, profile_summary, ray_profile
from ..studies.sweep import grid_values, sweep
from .output import dump, emit, holding_out, path_argument
from .progress import progress_bar


__all__ = ["DESCRIPTION", "HELP", "add_arguments", "run"]  # what cli/__init__ builds the command from

HELP = "bisection studies over aspect ratios: a grid of boxes, or exact thresholds along a ray"
DESCRIPTION = ("Run the bisection study for every box (1, b, c) of a grid (b <= c), or find exactly, "
               "along a ray of boxes such as (1, r, r), every r where the FVM-adequate count or the element set changes.")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    mode = parser.add_mutually_exclusive_group(required=True)
    mode.add_argument("--ratios", nargs=2, metavar=("B_MIN:B_MAX:STEPS", "C_MIN:C_MAX:STEPS"),
                      help="grid of b and c values, each MIN:MAX:STEPS (exact numbers)")
    mode.add_argument("--ray", metavar="1,r,r", help="a ray of boxes: three lengths, each 1 or r")
    parser.add_argument("--range", default="1:4", metavar="R_MIN:R_MAX", help="range of r along the ray (default 1:4)")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="processes for the grid (default: all cores)")
    parser.add_argument("--out", type=path_argument, metavar="DIR", help="also write JSON, PNG and pgfplots figures into DIR")
    parser.add_argument("--format", choices=("text", "json"), default="text",
                        help="text (default): a table; json: the counts as data")


@holding_out
def run(args: argparse.Namespace) -> int:
    if args.ray:
        return _ray(args)
    b_values = grid_values(args.ratios[0], "b range")
    c_values = grid_values(args.ratios[1], "c range")
    boxes = sum(1 for b in b_values for c in c_values if b <= c)
    if boxes == 0:
        raise InputError("the grid has no box with b <= c")
    with progress_bar(boxes, "sweep") as advance:
        results = sweep(b_values, c_values, jobs=max(1, args.jobs), progress=advance)
    data = {"boxes": results}
    if args.out:
        atomic_write(args.out / "sweep.json", dump(data, "json"))
        heatmap_png(results, args.out / "heatmap.png")
        heatmap_tex(results, args.out / "heatmap.tex")
        atomic_write(args.out / "figures.tex", environment().get_template("figures.tex.j2").render(files=["heatmap.tex"]))
    if args.format == "json":
        emit(data, "json")
    else:
        print(f"{'box':<28} {'FVM adequate':>12} {'(open)':>7} {'types':>6} {'elements':>9}")
        for row in results:
            print(f"{' x '.join(row['box']):<28} {row['fvm_adequate']:>12} {row['fvm_adequate_open']:>7} "
                  f"{row['types']:>6} {row['total']:>9}")
    return 0


def _ray(args: argparse.Namespace) -> int:
    ray = Ray.parse(args.ray)
    parts = args.range.split(":")
    if len(parts) != 2:
        raise InputError(f"range {args.range!r}: write R_MIN:R_MAX, for example 1:4")
    r_lo, r_hi = (parse_rational(p, "ray range") for p in parts)
    if not 0 < r_lo <= r_hi:
        raise InputError(f"range {args.range!r}: need 0 < R_MIN <= R_MAX")
    with progress_bar(4096, f"ray {ray.text}") as advance:
        steps = ray_profile(ray, r_lo, r_hi, progress=advance)
    data = profile_summary(ray, r_lo, r_hi, steps)
    if args.out:
        stem = "ray-" + ray.text.replace(",", "-")
        atomic_write(args.out / f"{stem}.json", dump(data, "json"))
        steps_png(data, args.out / f"{stem}.png")
        steps_tex(data, args.out / f"{stem}.tex")
        atomic_write(args.out / f"{stem}-figure.tex",
                     environment().get_template("figures.tex.j2").render(files=[f"{stem}.tex"]))
    if args.format == "json":
        emit(data, "json")
        return 0
    print(f"boxes ({ray.text}), r from {data['range'][0]} to {data['range'][1]}: exact steps")
    for step in data["steps"]:
        lo, hi = step["r_from"], step["r_to"]
        where = f"r = {lo}" if step["u_from"] == step["u_to"] else \
            f"{'[' if step['from_closed'] else '('}{lo}, {hi}{']' if step['to_closed'] else ')'}"
        print(f"  {where:<28} FVM adequate {step['fvm_adequate']:>5}   element types {step['types']:>3}")
    largest = data["largest_fully_adequate"]
    if largest:
        print(f"all 4096 configurations are adequate up to r = {largest['r']}"
              f"{' (included)' if largest['attained'] else ' (excluded)'}")
    return 0
