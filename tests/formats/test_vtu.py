"""A tessellation's VTU read back by meshio."""

from __future__ import annotations

import meshio
import numpy as np
import pytest

from cospherical import Configuration, tessellate
from cospherical.formats.vtu import write_vtu


@pytest.mark.oracle_meshio
def test_vtu_reads_back(tmp_path):
    for code, expect_polyhedra in (("888800000000", False), ("880000000000", True)):
        tess = tessellate(Configuration.from_code(code, ("1", "2", "4") if not expect_polyhedra else ("1", "1", "1")))
        path = tmp_path / f"{code}.vtu"
        write_vtu(tess, path)
        mesh = meshio.read(path)
        assert len(mesh.points) == len(tess.nodes)
        assert sum(len(block.data) for block in mesh.cells) == len(tess.elements)
        assert any(block.type.startswith("polyhedron") for block in mesh.cells) == expect_polyhedra
        hashes = sorted(int(x) for block in mesh.cell_data["type_hash"] for x in np.ravel(block))
        assert hashes == sorted(int(e.type.id.rsplit("-", 1)[1], 16) for e in tess.elements)
