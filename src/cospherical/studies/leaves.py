"""The octree-leaf family: the bisection configurations as a mesher meets them at octree leaves.

In a 2:1-balanced octree a leaf's points are the corners of every leaf touching
it: a midpoint on an edge where a smaller leaf touches that edge, the centre of a
face where the **face neighbour** is refined, and never a body point (nothing of
the mesh lies inside a leaf).  The four edges of a face can be split by the side
neighbours while the face neighbour stays whole, so the face point is data, not a
consequence of the edges as the paper's octree policy has it.  The family is
every edge mask with every admissible set of face points and no body point: 6210
configurations, each named by its whole-point-set code (``+f`` suffix).

The study is a bisection-style study (:func:`~cospherical.studies.engine.run_study`:
symmetry orbits over the whole point set, criteria, summaries, pattern tables);
its reports set the octree-policy bisection study of the same box beside it
(:func:`~cospherical.studies.summary.compared_with`).
"""

from __future__ import annotations

from itertools import combinations
from typing import Sequence

from ..choices import CRITERIA
from ..core.codes import point_suffix
from ..core.configuration import Box
from ..core.shapes import FACE_EDGES
from .engine import Progress, Study, bisection_codes, run_study

__all__ = ["leaf_codes", "run_leaves"]


def leaf_codes() -> list[str]:
    """Every octree-leaf configuration: each bisection edge mask with each admissible face set.

    A face is admissible when its four edges carry midpoints; there is no body point.

    Examples
    --------
    >>> codes = leaf_codes()
    >>> len(codes), codes[0], codes[-1]
    (6210, '000000000000+f', '888888888888+f012345')
    >>> [code for code in codes if code.startswith("888800000000")]
    ['888800000000+f', '888800000000+f4']
    """
    codes: list[str] = []
    for code in bisection_codes():
        split = [f for f in range(6) if all(code[k] == "8" for k in FACE_EDGES[f])]
        for size in range(len(split) + 1):
            codes.extend(code + "+" + point_suffix(faces, False) for faces in combinations(split, size))
    return codes


def run_leaves(box: Box, progress: Progress | None = None, criteria: Sequence[str] = CRITERIA,
               known: Sequence[Study] = ()) -> Study:
    """The leaf study of a box: every configuration of :func:`leaf_codes`, one per symmetry orbit.

    Parameters
    ----------
    box : Box
        The cuboid.
    progress : callable, optional
        Called with the number of configurations each finished orbit accounts for.
    criteria : sequence of str
        The criteria to apply (all three by default; ``("optimal",)`` skips the split search).
    known : sequence of Study
        Studies of the same box whose tessellations are taken where a leaf configuration has the
        same points (:func:`~cospherical.studies.engine.run_study`'s ``known``).

    Returns
    -------
    Study
        Named ``leaves``, face points ``explicit``; its codes are whole-point-set codes.

    Examples
    --------
    >>> study = run_leaves(Box.parse(["1", "1", "1"]), criteria=("optimal",))  # on the cube, every one is FVM-adequate
    >>> study.configurations, study.orbits, study.face_points, study.fvm_adequate, study.fvm_adequate_open
    (6210, 227, 'explicit', 6210, 6210)
    """
    return run_study("leaves", box, leaf_codes(), "explicit", progress=progress, criteria=criteria, known=known)
