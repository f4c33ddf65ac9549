"""The outside oracle (cospherical.mesh.dual.tetrahedral): TetGen's tetrahedra of the vertices, and its failures."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from cospherical.mesh.assembly import assemble
from cospherical.mesh.dual import mesh_dual

from ..test_dual import CACHES, OCTREES


def test_a_full_disk_under_tetgens_scratch_file_names_that_file(monkeypatch):
    # a failed write names no file (EFBIG from a file-size limit was 'cospherical: error: File too large')
    import errno

    from cospherical.mesh.dual import external_tetrahedra

    def full(*args, **kwargs):
        raise OSError(errno.EFBIG, "File too large")
    monkeypatch.setattr(np, "savetxt", full)
    with pytest.raises(OSError) as raised:
        external_tetrahedra(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]))
    assert raised.value.filename.endswith("points.node") and raised.value.errno == errno.EFBIG


@pytest.mark.oracle_tetgen
@pytest.mark.oracle_discretize
@pytest.mark.parametrize("name", ["sphere", "discretize points"])
def test_tetgen_tetrahedra_of_the_same_vertices_give_the_same_dual_exactly(name):
    """An independent tetrahedral Delaunay mesh (TetGen) of the vertices has the same dual, exactly.

    meshplex (control volumes of tetrahedral meshes) now demands a licence at import; this is
    its check: the tetrahedra split the co-spherical elements, so every control volume and
    every coefficient is the same fraction; the tetrahedra's extra edges (diagonals of
    polygon faces and through elements) get zero.
    """
    import shutil

    from cospherical.mesh.dual import external_tetrahedra

    assert shutil.which("tetgen"), "tetgen (Debian) is a test dependency: scripts/setup.sh installs it"
    tree = OCTREES[name]()
    mesh = assemble(tree, cache=CACHES.setdefault(tree.box.texts, {}))
    mixed = mesh_dual(mesh)
    tets, tool, flat = external_tetrahedra(mesh.vertices)
    assert tool == "tetgen" and flat == 0
    tetra = mesh_dual(mesh, (tets.astype(np.int32), np.full(len(tets), 4, dtype=np.int8)))

    def exact(values, denominator):
        return [Fraction(int(v), denominator) for v in values]

    assert exact(tetra.volume_exact, tetra.volume_denominator) == exact(mixed.volume_exact, mixed.volume_denominator)
    ours = dict(zip(map(tuple, mixed.edges.tolist()), exact(mixed.coefficient_exact, mixed.coefficient_denominator)))
    theirs = dict(zip(map(tuple, tetra.edges.tolist()), exact(tetra.coefficient_exact, tetra.coefficient_denominator)))
    assert set(ours) <= set(theirs) and len(theirs) > len(ours)
    assert all(theirs[pair] == ours.get(pair, 0) for pair in theirs)


