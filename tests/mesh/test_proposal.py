"""A cluster's tetrahedra: Qhull's proposal, checked in integers, and the exact engine give the same cells."""

from __future__ import annotations

import numpy as np
import pytest

from cospherical.core.configuration import Box
from cospherical.mesh.assembly import assemble
from cospherical.mesh.checks import grid_weights
from cospherical.mesh.merged_cells import same_sphere
from cospherical.mesh.octree import build_octree, parse_shape
from cospherical.mesh.proposal import cluster_tetrahedra, qhull_proposal


@pytest.fixture(scope="module")
def leaf():
    return assemble(build_octree(Box.parse(["1", "2", "4"]), 2, [parse_shape("point:0.1,0.1,0.1")]))


def _cells(mesh, tets: np.ndarray) -> set[frozenset[int]]:
    """The tetrahedra grouped by exact circumcentre: each group's vertex set."""
    group = same_sphere(mesh, tets, grid_weights(mesh))
    return {frozenset(tets[group == g].reshape(-1).tolist()) for g in np.unique(group).tolist()}


@pytest.mark.oracle_qhull
def test_qhull_and_the_exact_engine_give_the_same_cells(leaf):
    ids = np.arange(len(leaf.vertices))
    qhull, exact = cluster_tetrahedra(leaf, ids, "qhull"), cluster_tetrahedra(leaf, ids, "exact")
    assert len(qhull) and _cells(leaf, qhull) == _cells(leaf, exact)
    # a proposal that fails goes to the exact engine
    coords = leaf.vertices.astype(np.int64)
    assert qhull_proposal(leaf, coords, lambda points: 1 / 0) is None
    assert _cells(leaf, cluster_tetrahedra(leaf, ids, "qhull", lambda points: 1 / 0)) == _cells(leaf, exact)
