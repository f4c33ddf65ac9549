"""The report's figures of a dual (cospherical.mesh.dual.summary): the mixed mesh beside TetGen's of its vertices."""

from __future__ import annotations

import shutil

from cospherical.core.configuration import Box
from cospherical.mesh.assembly import assemble
from cospherical.mesh.dual import dual_summary, mesh_dual
from cospherical.mesh.octree import build_octree, parse_shape

from ..test_dual import CACHES


def test_the_summary_counts_the_mixed_mesh_and_tetgens_of_the_same_vertices():
    assert shutil.which("tetgen"), "tetgen (Debian) is a test dependency: scripts/setup.sh installs it"
    box = Box.parse(["1", "1", "1"])
    mesh = assemble(build_octree(box, 2, [parse_shape("point:1/3,1/5,1/7")]), cache=CACHES.setdefault(box.texts, {}))
    dual = mesh_dual(mesh)
    summary = dual_summary(dual, len(mesh), 1234, tetrahedral=True)
    figures, mixed, tets = summary.dual, summary.dual.mixed, summary.dual.tetrahedral
    assert summary.negative_coefficients == dual.negative_coefficients()
    assert figures.volume_sum == "1" and figures.edges == len(dual.edges) == mixed.edges
    assert mixed.to_dict() == {"elements": len(mesh), "edges": len(dual.edges), "faces": 1234,
                               "nonzeros": len(dual.vertices) + 2 * len(dual.edges)}
    assert figures.boundary_vertices == int(dual.boundary.sum())
    # TetGen splits the co-spherical elements: more elements and more edges, the same vertices; Euler's
    # formula for a tetrahedralised ball (V - E + F - T = 1) holds for its counts
    assert tets.tool == "tetgen" and tets.flat == 0
    assert tets.elements > mixed.elements and tets.edges >= mixed.edges
    assert len(dual.vertices) - tets.edges + tets.faces - tets.elements == 1
    assert tets.nonzeros == len(dual.vertices) + 2 * tets.edges
    assert dual_summary(dual, len(mesh), 1234).dual.tetrahedral is None  # the outside run is asked for
