"""Gmsh files read back by Gmsh's own API and by meshio: physical groups, names, elements, nodes, orientation."""

from __future__ import annotations

import numpy as np
import pytest

from cospherical.core.configuration import Box
from cospherical.errors import InputError
from cospherical.formats.gmsh import GMSH_VERSIONS, msh_bytes, write_msh
from cospherical.mesh.assembly import assemble
from cospherical.mesh.octree import build_octree, parse_shape
from cospherical.mesh.tetrahedra import SIDES, simplex_mesh

FORMATS = [(version, binary) for version in GMSH_VERSIONS for binary in (False, True)]


@pytest.fixture(scope="module")
def simplices():
    """A graded 1 x 2 x 4 tree: polygon faces, every side of the box a physical surface."""
    mesh = assemble(build_octree(Box.parse(["1", "2", "4"]), 3, [parse_shape("point:1/5,3/10,2/5")]))
    return simplex_mesh(mesh)


def read_with_gmsh(path):
    """Physical groups (name -> (dimension, element tags' node rows)) and nodes, as Gmsh's API gives them."""
    import gmsh

    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(str(path))
        groups = {}
        for dim, tag in gmsh.model.getPhysicalGroups():
            rows = []
            for entity in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
                types, _, nodes = gmsh.model.mesh.getElements(dim, entity)
                for kind, flat in zip(types, nodes):
                    width = gmsh.model.mesh.getElementProperties(kind)[3]
                    rows.append(np.asarray(flat, dtype=np.int64).reshape(-1, width))
            groups[gmsh.model.getPhysicalName(dim, tag)] = (dim, np.concatenate(rows))
        tags, coords, _ = gmsh.model.mesh.getNodes()
        order = np.argsort(tags)
        return groups, np.asarray(tags)[order], np.asarray(coords).reshape(-1, 3)[order]
    finally:
        gmsh.finalize()


@pytest.mark.parametrize("version,binary", FORMATS)
def test_gmsh_reads_the_groups_elements_and_nodes(simplices, tmp_path, version, binary):
    path = tmp_path / "mesh.msh"
    write_msh(simplices, path, version, binary)
    groups, tags, coords = read_with_gmsh(path)
    assert sorted(groups) == sorted(("domain", *SIDES))
    dim, tets = groups["domain"]
    assert dim == 3 and np.array_equal(tets - 1, simplices.tetrahedra)
    for k, side in enumerate(SIDES):
        dim, triangles = groups[side]
        assert dim == 2 and np.array_equal(triangles - 1, simplices.triangles[simplices.surface == k])
    assert np.array_equal(tags, np.arange(1, len(simplices.points) + 1))
    assert np.array_equal(coords, simplices.points)  # 17 digits (text) or the doubles themselves (binary): exact
    d = coords[tets - 1]
    assert (np.einsum("ij,ij->i", d[:, 1] - d[:, 0], np.cross(d[:, 2] - d[:, 0], d[:, 3] - d[:, 0])) > 0).all()


@pytest.mark.oracle_meshio
@pytest.mark.parametrize("version,binary", FORMATS)
def test_meshio_reads_it(simplices, tmp_path, version, binary):
    import meshio

    path = tmp_path / "mesh.msh"
    write_msh(simplices, path, version, binary)
    back = meshio.read(path)
    assert np.array_equal(back.points, simplices.points)
    tets = np.concatenate([c.data for c in back.cells if c.type == "tetra"])
    triangles = np.concatenate([c.data for c in back.cells if c.type == "triangle"])
    assert np.array_equal(tets, simplices.tetrahedra) and np.array_equal(triangles, simplices.triangles)
    assert {name: int(tag) for name, (tag, _) in back.field_data.items()} == {
        "domain": 1, **{side: 2 + k for k, side in enumerate(SIDES)}}


@pytest.mark.parametrize("version,binary", FORMATS)
def test_deterministic_bytes(simplices, tmp_path, version, binary):
    write_msh(simplices, tmp_path / "a.msh", version, binary)
    assert (tmp_path / "a.msh").read_bytes() == msh_bytes(simplices, version, binary)


@pytest.mark.parametrize("name", ['a"b', "two\nlines", "", "tab\there"])
def test_names_that_would_break_the_file_are_refused(simplices, name):
    from dataclasses import replace

    with pytest.raises(InputError, match="physical name"):
        msh_bytes(replace(simplices, volumes=(name,)))


def test_unknown_version_is_refused(simplices):
    with pytest.raises(InputError, match="Gmsh version"):
        msh_bytes(simplices, "3.0")
