"""A cluster's Delaunay tetrahedra: Qhull proposes them in floats, integers check, the exact engine where either fails.

The tetrahedra of a cluster's vertices that :func:`~cospherical.mesh.delaunay.retessellate`
merges into cells and then proves (its module says how, and why only the proposal is
inexact).  Qhull hands back arrays and is fast; it fails on boxes of extreme aspect ratio
(1e-12 x 1 x 3e9: its first simplex is flat in floats) and float rounding on thin boxes
flips faces, which a cheap integer check across the tetrahedra's faces catches.  The
exact engine (:func:`~cospherical.core.incremental_delaunay.delaunay_tetrahedra`,
Bowyer-Watson in Python integers, about 3.6 times Qhull's path's CPU) takes over there.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..core.geometry import six_volumes, sphere_sides
from ..core.incremental_delaunay import delaunay_tetrahedra
from .assembly import Mesh
from .checks import grid_weights

__all__ = ["Proposal", "cluster_tetrahedra", "qhull_proposal"]

# What proposes a cluster's tetrahedra in place of Qhull (a seam for tests): real points -> an object with
# Qhull's ``simplices``, ``neighbors`` and ``coplanar`` (scipy.spatial.Delaunay's).
Proposal = Callable[[np.ndarray], Any]


def cluster_tetrahedra(mesh: Mesh, ids: np.ndarray, engine: str = "qhull",
                       proposal: Proposal | None = None) -> np.ndarray:
    """The Delaunay tetrahedra of a cluster's vertices (global ids, in and out), without flat ones.

    ``qhull``: Qhull proposes them in floats and integers check the proposal; where
    Qhull fails (boxes of extreme aspect ratio, 1e-12 x 1 x 3e9: its first simplex
    is flat in floats) or the check does, the exact engine
    (:func:`~cospherical.core.incremental_delaunay.delaunay_tetrahedra`) makes them.
    ``exact``: the exact engine alone.
    """
    coords = mesh.vertices[ids].astype(np.int64)
    if engine == "qhull":
        simplices = qhull_proposal(mesh, coords, proposal)
        if simplices is not None:
            proposed: np.ndarray = ids[simplices]
            return proposed
    tets: np.ndarray = ids[np.array(delaunay_tetrahedra(coords.tolist(), grid_weights(mesh)),
                                    dtype=np.int64).reshape(-1, 4)]
    return tets


def qhull_proposal(mesh: Mesh, coords: np.ndarray, proposal: Proposal | None = None) -> np.ndarray | None:
    """Qhull's solid tetrahedra of the points (indices into ``coords``), or ``None`` when Qhull or the check fails.

    The check, in integers: across every face between two solid tetrahedra the far
    vertex is not strictly inside the near one's sphere (a tiling of the hull that
    is not Delaunay has such a face; float rounding on thin boxes makes exactly that
    kind of flip); it is cheap and saves a second pass, but it proves nothing alone:
    :func:`~cospherical.mesh.delaunay.retessellate` proves the cells.  ``proposal(real_points)``: a triangulation
    with Qhull's ``simplices``, ``neighbors`` and ``coplanar`` in place of Qhull's (a seam for tests).
    """
    from scipy.spatial import Delaunay

    real = (coords - coords.min(axis=0)) * (np.array(mesh.box.to_float()) / mesh.grid)
    try:
        triangulation = (proposal or (lambda points: Delaunay(points, qhull_options="Qbb Qc Qz Q12 Qt")))(real)
    except Exception:  # Qhull's float precision errors: the exact engine takes the cluster
        return None
    if len(triangulation.coplanar):
        return None
    simplices = triangulation.simplices.astype(np.int64)
    p = coords[simplices]  # (tets, 4, 3)
    solid = six_volumes(p) != 0
    # each face between two solid tetrahedra, once (near < far): the far one's vertex across it
    near, face = np.nonzero(solid[:, None] & (triangulation.neighbors > np.arange(len(simplices))[:, None]))
    far = triangulation.neighbors[near, face]
    pick = solid[far]
    near, far = near[pick], far[pick]
    across = simplices[far, np.argmax(triangulation.neighbors[far] == near[:, None], axis=1)]
    if len(near) and sphere_sides(p[near], coords[across], grid_weights(mesh)).min() < 0:
        return None
    kept: np.ndarray = simplices[solid]
    return kept
