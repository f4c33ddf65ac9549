"""Sweep figures: a heat map over (b, c) and a step plot along a ray, as PNG and as pgfplots."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType
from typing import Any

from ..core.exact import Length
from ..files.yamlio import atomic_write
from .latex import environment, save_png

__all__ = ["heatmap_png", "heatmap_tex", "steps_png", "steps_tex"]


def _value(text: str) -> float:
    return float(Length.parse(text))


def _pyplot() -> ModuleType:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def heatmap_png(boxes: list[dict[str, Any]], path: Path) -> None:
    """FVM-adequate configurations of every box (1, b, c) of a sweep, b <= c."""
    plt = _pyplot()
    bs = sorted({_value(x["box"][1]) for x in boxes})
    cs = sorted({_value(x["box"][2]) for x in boxes})
    import numpy as np

    grid = np.full((len(cs), len(bs)), np.nan)
    for x in boxes:
        grid[cs.index(_value(x["box"][2])), bs.index(_value(x["box"][1]))] = x["fvm_adequate"]
    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    def edges(values: list[float]) -> list[float]:
        if len(values) == 1:
            return [values[0] - 0.5, values[0] + 0.5]
        mids = [(a + b) / 2 for a, b in zip(values, values[1:])]
        return [2 * values[0] - mids[0], *mids, 2 * values[-1] - mids[-1]]
    mesh = ax.pcolormesh(edges(bs), edges(cs), np.ma.masked_invalid(grid), cmap="viridis", vmin=0, vmax=4096)
    fig.colorbar(mesh, ax=ax, label="FVM-adequate configurations (of 4096)")
    ax.set_xlabel("b")
    ax.set_ylabel("c")
    ax.set_title("Boxes (1, b, c), bisection configurations")
    ax.set_aspect("equal")
    fig.tight_layout()
    save_png(fig, path)


def heatmap_tex(boxes: list[dict[str, Any]], path: Path) -> None:
    rows = [{"b": f"{_value(x['box'][1]):.6g}", "c": f"{_value(x['box'][2]):.6g}", "fvm": x["fvm_adequate"]}
            for x in boxes]
    count = max(1, len({r["b"] for r in rows}))
    text = environment().get_template("heatmap.tex.j2").render(
        rows=rows, title="FVM-adequate configurations, boxes (1, b, c)", mark_size=f"{max(2.0, 60 / count):.1f}")
    atomic_write(path, text)


def _step_points(profile: dict[str, Any]) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    line, marks = [], []
    for step in profile["steps"]:
        lo, hi = _value(step["r_from"]), _value(step["r_to"])
        if lo == hi:
            marks.append({"r": f"{lo:.6g}", "fvm": step["fvm_adequate"]})
        else:
            line.append({"r": f"{lo:.6g}", "fvm": step["fvm_adequate"]})
            line.append({"r": f"{hi:.6g}", "fvm": step["fvm_adequate"]})
    return line, marks


def steps_png(profile: dict[str, Any], path: Path) -> None:
    """FVM-adequate configurations along the ray: a line on each interval, a dot at each threshold."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 3.6))
    for step in profile["steps"]:
        lo, hi = _value(step["r_from"]), _value(step["r_to"])
        if lo == hi:
            ax.plot([lo], [step["fvm_adequate"]], "o", color="crimson", markersize=4)
        else:
            ax.plot([lo, hi], [step["fvm_adequate"]] * 2, color="navy", linewidth=2)
    ax.set_xlabel("r")
    ax.set_ylabel("FVM-adequate configurations")
    ax.set_ylim(0, 4300)
    ax.grid(True, alpha=0.3)
    ax.set_title(f"Boxes ({profile['ray']}), bisection configurations")
    fig.tight_layout()
    save_png(fig, path)


def steps_tex(profile: dict[str, Any], path: Path) -> None:
    line, marks = _step_points(profile)
    text = environment().get_template("steps.tex.j2").render(
        points=line, marks=marks, title=f"FVM-adequate configurations, boxes ({profile['ray']})")
    atomic_write(path, text)
