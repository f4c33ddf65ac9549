"""The tetrahedral split: conforming, positive, volume-exact, and the same dual exactly (signed pieces)."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
from hypothesis import given

from cospherical.core.configuration import Box
from cospherical.core.geometry import six_volumes
from cospherical.mesh.assembly import assemble
from cospherical.mesh.delaunay import delaunay_mesh
from cospherical.mesh.dual import mesh_dual
from cospherical.mesh.octree import build_octree, parse_shape
from cospherical.mesh.tetrahedra import boundary_triangles, split_tetrahedra

from .test_dual import CACHES, PROPERTY, octrees


def exact(values, denominator):
    return [Fraction(int(v), denominator) for v in values]


def assert_split_is_exact(mesh):
    tets = split_tetrahedra(mesh)
    vertices = np.asarray(mesh.vertices, dtype=np.int64)
    volumes = six_volumes(vertices[tets.nodes])
    assert (volumes > 0).all()  # positively oriented (VTK's and Gmsh's convention), none flat
    assert int(volumes.sum()) == 6 * int(mesh.grid) ** 3  # they fill the domain exactly
    assert set(tets.parent.tolist()) == set(range(len(mesh)))
    assert (np.diff(tets.parent) >= 0).all()
    # conforming: each triangle is met twice (inside) or once (on the domain's sides, as boundary_triangles splits it)
    faces = np.sort(tets.nodes[:, [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]]].reshape(-1, 3), axis=1)
    unique, counts = np.unique(faces, axis=0, return_counts=True)
    assert counts.max() == 2
    outer = np.sort(boundary_triangles(mesh).nodes, axis=1)
    assert sorted(map(tuple, unique[counts == 1].tolist())) == sorted(map(tuple, outer.tolist()))
    # the dual of the tetrahedra, signed pieces, equals the elements' dual; the added edges couple 0, exactly
    own, split = mesh_dual(mesh), mesh_dual(mesh, (tets.nodes, np.full(len(tets), 4)))
    mine = dict(zip(map(tuple, own.edges.tolist()), exact(own.coefficient_exact, own.coefficient_denominator)))
    theirs = dict(zip(map(tuple, split.edges.tolist()), exact(split.coefficient_exact, split.coefficient_denominator)))
    assert set(mine) <= set(theirs)
    assert all(theirs[edge] == q for edge, q in mine.items())
    assert all(theirs[edge] == 0 for edge in set(theirs) - set(mine))
    assert exact(own.volume_exact, own.volume_denominator) == exact(split.volume_exact, split.volume_denominator)
    assert exact(own.boundary_area_exact.reshape(-1), own.boundary_area_denominator) == exact(
        split.boundary_area_exact.reshape(-1), split.boundary_area_denominator)
    return tets, set(theirs) - set(mine)


@PROPERTY
@given(octrees())
def test_the_split_conforms_and_keeps_the_dual_exactly(mesh):
    assert_split_is_exact(mesh)


def test_cells_of_the_global_delaunay_subdivision_split_exactly():
    """1 x 2 x 4: leaves re-tessellated together, cells spanning leaves; polygon faces get diagonals."""
    box = Box.parse(["1", "2", "4"])
    leaf = assemble(build_octree(box, 3, [parse_shape("point:1/5,3/10,2/5")]), cache=CACHES.setdefault(box.texts, {}))
    mesh, _, _ = delaunay_mesh(leaf, "global")
    assert mesh.cells is not None and len(mesh.cells)
    _, added = assert_split_is_exact(mesh)
    assert added  # diagonals were added, and got coupling 0


def test_the_split_is_deterministic_and_regions_follow_the_parent():
    box = Box.parse(["1", "1", "1"])
    mesh = assemble(build_octree(box, 2, [parse_shape("sphere:0.5,0.5,0.5,0.3")]), cache=CACHES.setdefault(box.texts, {}))
    first, second = split_tetrahedra(mesh), split_tetrahedra(mesh)
    assert np.array_equal(first.nodes, second.nodes) and np.array_equal(first.parent, second.parent)
    assert (first.region == 0).all()


def test_a_device_gives_a_volume_per_region_and_a_surface_per_contact_and_interface():
    """The MOS capacitor (substrate and oxide, bulk and gate contacts) at level 3: every contact and interface
    triangle is a face of the tetrahedra, met on the right side, and the regions keep their elements' volume."""
    from dataclasses import replace
    from pathlib import Path

    from cospherical.api.mesh import build_mesh
    from cospherical.formats.device_file import read_device
    from cospherical.mesh.tetrahedra import simplex_mesh

    device = read_device(Path(__file__).resolve().parents[2] / "examples" / "devices" / "mos-capacitor.yaml")
    mesh = build_mesh(device=replace(device, levels=3)).assembled
    simplices = simplex_mesh(mesh)
    assert simplices.volumes == ("substrate", "oxide")
    assert simplices.surfaces == ("bulk", "gate", "substrate|oxide")
    tets = split_tetrahedra(mesh)
    assert np.array_equal(simplices.volume, mesh.element_region[tets.parent])
    vertices = np.asarray(mesh.vertices, dtype=np.int64)
    volumes = six_volumes(vertices[simplices.tetrahedra])
    grid = int(mesh.grid)
    assert [int(volumes[simplices.volume == r].sum()) for r in range(2)] == [6 * grid ** 3 * 3 // 4,
                                                                            6 * grid ** 3 // 4]
    # oriented faces of the tetrahedra, outward, with the region of the tetrahedron they bound
    outward = simplices.tetrahedra[:, [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]]]
    faces = {}
    for tet, region in zip(outward.tolist(), simplices.volume.tolist()):
        for face in tet:
            faces.setdefault(tuple(sorted(face)), []).append(region)
    region_of = {"bulk": [0], "gate": [1], "substrate|oxide": [0, 1]}  # bulk on the substrate, gate on the oxide
    for k, name in enumerate(simplices.surfaces):
        triangles = simplices.triangles[simplices.surface == k]
        assert len(triangles)
        sides = [faces[tuple(sorted(t))] for t in triangles.tolist()]
        assert all(sorted(s) == region_of[name] for s in sides)


def test_a_device_of_one_region_gives_its_contacts_and_no_interface(tmp_path):
    """A device of one region (a box, contacts on two of its sides, no interface): its Gmsh file has the
    region's volume and the contacts' surfaces, each contact's triangles covering its rectangle (a device
    without interfaces, such as examples/devices/l-shape.yaml, was a ValueError traceback)."""
    import meshio

    from cospherical.api.mesh import build_mesh
    from cospherical.formats.gmsh import write_msh
    from cospherical.mesh.device import Contact, Device, Region
    from cospherical.mesh.tetrahedra import simplex_mesh

    F = Fraction
    device = Device("bar", (Region("si", "Si", ((F(0), F(0), F(0), F(2), F(1), F(1)),)),),
                    (Contact("left", "si", (F(0), F(0), F(0), F(0), F(1), F(1))),
                     Contact("top", "si", (F(1), F(0), F(1), F(2), F(1), F(1)))), (), 0)
    built = build_mesh(device=device, uniform=False)
    simplices = simplex_mesh(built.assembled)
    assert simplices.volumes == ("si",) and simplices.surfaces == ("left", "top")
    for k in range(2):  # 1 x 1 each
        p = simplices.points[simplices.triangles[simplices.surface == k]]
        assert np.isclose(0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum(), 1)
    write_msh(simplices, tmp_path / "mesh.msh")
    assert sorted(meshio.read(tmp_path / "mesh.msh").field_data) == ["left", "si", "top"]
