"""The outside oracle: a tetrahedral Delaunay mesh of the same vertices by a mesher nobody here wrote
(TetGen, else Qhull), and its counts, the tetrahedral side of the report's comparison."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ...core.geometry import six_volumes
from ..octree import distinct
from ..report_sections import TetrahedralCounts

__all__ = ["TETRAHEDRAL_LIMIT", "external_tetrahedra", "tetrahedral_counts"]

TETRAHEDRAL_LIMIT = 1_000_000  # vertices: above it the tetrahedral comparison is skipped (minutes and gigabytes)


def external_tetrahedra(grid_vertices: NDArray[np.integer]) -> tuple[NDArray[np.int64], str, int]:
    """A tetrahedral Delaunay mesh of integer points by an outside mesher: (tetrahedra, the tool, flat ones left out).

    TetGen (``tetgen``, Debian; exact predicates) when it is installed; else scipy's
    Qhull, whose flat tetrahedra (co-spherical points it triangulates through a
    zero-volume sliver, decided on the integers) are left out and counted.
    """
    import shutil
    import subprocess
    import tempfile

    points = np.asarray(grid_vertices, dtype=np.int64)
    tool = shutil.which("tetgen")
    if tool:
        with tempfile.TemporaryDirectory() as folder:
            node = Path(folder) / "points.node"
            rows = np.column_stack([np.arange(len(points)), points])
            try:
                with open(node, "w") as handle:
                    handle.write(f"{len(points)} 3 0 0\n")
                    np.savetxt(handle, rows, fmt="%d")
            except OSError as error:  # a write that fails (a full disk) names no file: name the scratch file
                raise OSError(error.errno, error.strerror, str(node)) from None
            subprocess.run([tool, "-Q", "-F", "-N", str(node)], check=True, capture_output=True, timeout=3600)
            tets = np.loadtxt(Path(folder) / "points.1.ele", dtype=np.int64, skiprows=1, ndmin=2)[:, 1:5]
        return tets, "tetgen", 0
    from scipy.spatial import Delaunay

    tets = Delaunay(points.astype(np.float64)).simplices.astype(np.int64)
    keep = six_volumes(points[tets]) != 0
    return tets[keep], "qhull", int((~keep).sum())


def tetrahedral_counts(grid_vertices: NDArray[np.integer]) -> TetrahedralCounts:
    """Elements, edges, faces and matrix nonzeros of a tetrahedral Delaunay mesh of the same vertices.

    The paper's claim is that mixed elements need fewer of each; this is the
    tetrahedral side of that comparison (:func:`external_tetrahedra`).
    """
    points = np.asarray(grid_vertices, dtype=np.int64)
    tets, tool, flat = external_tetrahedra(points)
    tets = np.sort(tets, axis=1)
    n = np.int64(len(points))
    pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    edges = distinct(np.concatenate([tets[:, a] * n + tets[:, b] for a, b in pairs]))
    triples = [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)]
    faces = distinct(np.concatenate([(tets[:, a] * n + tets[:, b]) * n + tets[:, c] for a, b, c in triples]))
    return TetrahedralCounts(tool, int(len(tets)), int(len(edges)), int(len(faces)),
                             int(len(points) + 2 * len(edges)), flat)
