"""A picture of a meshed octree: a cut through the mesh, each element's section coloured by its type."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..mesh.assembly import Mesh
from .latex import save_png

__all__ = ["cut_png", "cut_polygons"]


def cut_polygons(mesh: Mesh, at: float = 0.5) -> tuple[list[np.ndarray], list[str]]:
    """The sections of the elements by the plane z = ``at`` (fraction of the domain height), in real x, y.

    The plane is moved by a third of the finest grid step off ``at`` so that no face
    lies in it (a section is then always a proper convex polygon, its corners where
    the element's edges cross the plane).  Computed per block of alike elements (a configuration's
    element on all its leaves, a cell shape): those whose edges cross alike share one array.
    Returns the polygons and each one's element type id.
    """
    grid = mesh.grid
    z0 = round(at * grid) + 1 / 3
    scale = np.array(mesh.box.to_float()) / grid
    polygons, types = [], []
    for _, nodes, faces, type_id in mesh.blocks():
        z = mesh.vertices[nodes, 2]  # (elements, nodes)
        crossing = np.flatnonzero((z.min(axis=1) < z0) & (z.max(axis=1) > z0))
        if not len(crossing):
            continue
        edges = sorted({tuple(sorted((c[i], c[(i + 1) % len(c)]))) for c in faces for i in range(len(c))})
        a = nodes[np.ix_(crossing, [p for p, _ in edges])]  # (crossing elements, edges): vertex ids
        b = nodes[np.ix_(crossing, [q for _, q in edges])]
        pa, pb = mesh.vertices[a].astype(float), mesh.vertices[b].astype(float)  # (elements, edges, 3)
        za, zb = pa[..., 2] - z0, pb[..., 2] - z0
        cut = za * zb < 0
        masks = (cut.astype(np.int64) << np.arange(len(edges))).sum(axis=1)
        for mask in np.unique(masks).tolist():
            rows = np.flatnonzero(masks == mask)
            which = np.flatnonzero(cut[rows[0]])
            ra, rb = pa[rows][:, which], pb[rows][:, which]  # (rows, corners, 3)
            t = (za[rows][:, which] / (za[rows][:, which] - zb[rows][:, which]))[..., None]
            xy = (ra + t * (rb - ra))[..., :2]
            centre = xy.mean(axis=1, keepdims=True)
            angle = np.arctan2(xy[..., 1] - centre[..., 1], xy[..., 0] - centre[..., 0])
            xy = np.take_along_axis(xy, np.argsort(angle, axis=1)[..., None], axis=1) * scale[:2]
            polygons.extend(xy)
            types.extend([type_id] * len(rows))
    return polygons, types


def cut_png(mesh: Mesh, path: Path, title: str = "", at: float = 0.5, legend: int = 10) -> None:
    """Write the cut through the mesh at z = ``at`` as PNG, elements coloured by type (legend: the commonest)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection
    from matplotlib.patches import Patch

    polygons, types = cut_polygons(mesh, at)
    counts: dict[str, int] = {}
    for t in types:
        counts[t] = counts.get(t, 0) + 1
    order = sorted(counts, key=lambda t: (-counts[t], t))
    palette = plt.get_cmap("tab20").colors
    colour = {t: palette[i % len(palette)] for i, t in enumerate(order)}
    a, b, _ = mesh.box.to_float()
    fig, ax = plt.subplots(figsize=(10, 6.5 * min(2.0, max(0.6, b / a))))
    fig.subplots_adjust(left=0.07, right=0.66, top=0.92, bottom=0.08)  # room for the legend on the right
    ax.add_collection(PolyCollection(polygons, facecolors=[colour[t] for t in types], edgecolors="black",
                                     linewidths=0.15))
    ax.set_xlim(0, a)
    ax.set_ylim(0, b)
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_title(title or f"cut at z = {at:g} of the domain height", fontsize=8, wrap=True)

    def label(t: str) -> str:
        info = mesh.types.get(t, {})
        return f"{info.get('name', t)} ({counts[t]})"

    shown = order[:legend]
    ax.legend(handles=[Patch(facecolor=colour[t], edgecolor="black", label=label(t)) for t in shown],
              loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7, title="element type (sections)",
              title_fontsize=7)
    save_png(fig, path, dpi=130)
