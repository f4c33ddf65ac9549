"""The exact whole-mesh checks against a brute force."""

from __future__ import annotations

import numpy as np

from cospherical.core.configuration import Box
from cospherical.mesh.assembly import assemble
from cospherical.mesh.checks import check_circumcenters, check_delaunay
from cospherical.mesh.octree import build_octree, parse_shape

BRICK = Box.parse(["1", "2", "4"])


def test_global_delaunay_equals_brute_force_on_a_brick():
    """The 1x2x4 octree is not globally Delaunay; the exact check agrees with brute force over all vertices."""
    mesh = assemble(build_octree(BRICK, 4, [parse_shape("sphere:0.5,1,2,0.6")]))
    found = check_delaunay(mesh)
    conn, sizes = mesh.connectivity()
    points = mesh.vertices * (np.array(BRICK.to_float()) / mesh.grid)
    pairs = elements = 0
    for e in range(len(mesh)):
        nodes = conn[e, :sizes[e]]
        x = points[nodes]
        centre = np.linalg.lstsq(2 * (x[1:] - x[0]), (x[1:] ** 2).sum(1) - (x[0] ** 2).sum(), rcond=None)[0]
        d2 = ((points - centre) ** 2).sum(1)
        d2[nodes] = np.inf
        inside = int((d2 < ((x[0] - centre) ** 2).sum() * (1 - 1e-9)).sum())
        pairs, elements = pairs + inside, elements + (inside > 0)
    assert (found["delaunay_violating_pairs"], found["delaunay_violations"]) == (pairs, elements)
    assert found["delaunay_violations"] > 0
    assert check_circumcenters(mesh)["leaves_not_fvm_adequate"] > 0
