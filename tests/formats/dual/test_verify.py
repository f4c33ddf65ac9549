"""Verifying ``dual.npz`` (``cospherical check``): re-signed edits that keep every sum, elements that overlap
and leave a hole, too much hull work, forged devices refused; a version 4 device dual read and checked."""

from __future__ import annotations

import json

import numpy as np
import pytest

from .forged import KUHN, OTHER_DIAGONAL, _edited, _forged_dual, _resigned, _with_contact_faces


def test_a_resigned_edit_that_keeps_every_sum_is_refused_naming_the_edge(dual_run, tmp_path, capsys):
    # +k on one coefficient and -k on another (floats made to agree): every identity check makes is a sum,
    # so only computing the dual again from the file's elements can tell
    from cospherical.cli import main
    from cospherical.formats.dual import read_dual

    good = dual_run / "a" / "dual.npz"
    dual = read_dual(good)
    interior = np.flatnonzero(~dual.boundary[dual.edges].all(axis=1))
    a, b = int(interior[3]), int(interior[-5])
    factor = dual.volume_factor / dual.coefficient_denominator

    def balanced_coefficients(arrays):
        arrays["coefficient_exact"][[a, b]] += [7, -7]
        arrays["coefficient"][[a, b]] = arrays["coefficient_exact"][[a, b]] * factor
        arrays["area"][[a, b]] = arrays["coefficient"][[a, b]] * arrays["length"][[a, b]]
        return ["coefficient_exact", "coefficient", "area"]

    def balanced_volumes(arrays):
        arrays["volume_exact"][[0, 5]] += [3, -3]
        return ["volume_exact"]

    def a_float_alone(arrays):
        arrays["coefficient"][b] *= 1.5
        return ["coefficient"]

    def a_vertex_twice(arrays):
        arrays["element_nodes"][2, 1] = arrays["element_nodes"][2, 0]
        return ["element_nodes"]

    def an_element_twice(arrays):  # in another vertex order: refused in bulk, before the recomputation
        size = int(arrays["element_sizes"][4])
        arrays["element_nodes"][1] = -1
        arrays["element_nodes"][1, :size] = arrays["element_nodes"][4, :size][::-1]
        arrays["element_sizes"][1] = size
        return ["element_nodes", "element_sizes"]

    def a_vertex_moved_onto_another(arrays):  # an element with an edge of length 0: a ZeroDivisionError before
        arrays["grid_vertices"][dual.element_nodes[0, 1]] = arrays["grid_vertices"][dual.element_nodes[0, 0]]
        return ["grid_vertices"]

    i, j = dual.edges[min(a, b)]
    first, second = sorted(dual.element_nodes[0, :2].tolist())
    for edit, needle in ((balanced_coefficients, f"member coefficient_exact: edge {i}-{j} "),
                         (balanced_volumes, "member volume_exact: vertex 0 "),
                         (a_float_alone, f"member coefficient: edge {dual.edges[b, 0]}-{dual.edges[b, 1]} "),
                         (a_vertex_twice, "member element_nodes: element 2 names a vertex twice"),
                         (an_element_twice, "member element_nodes: elements 1 and 4 have the same vertices"),
                         (a_vertex_moved_onto_another, f"member grid_vertices: vertices {first} and {second} are "
                                                       "one grid point")):
        target = tmp_path / f"{edit.__name__}.npz"
        _edited(good, target, edit)
        if edit not in (a_vertex_twice, an_element_twice):  # the reader refuses those itself
            again = read_dual(target)
            assert again.volume_sum() == 1 and again.boundary_area_sums() == (2, 2, 2)
        capsys.readouterr()
        assert main(["check", str(target)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and needle in err and "Traceback" not in err, (needle, err)


def test_elements_whose_exact_hulls_are_too_much_work_are_refused_before_any_geometry(dual_run, tmp_path, capsys,
                                                                                         monkeypatch):
    """Re-signed elements of 64 co-spherical vertices, each a different shape: every distinct shape costs
    an exact hull (about 0.1 CPU-s at 64 vertices), so a small file of many of them would keep check busy
    for hours; the work is bounded from the elements alone, before any hull is computed."""
    from cospherical.cli import main
    from cospherical.formats.dual import read_dual
    from cospherical.mesh.dual import shapes as mesh_dual_module

    good = dual_run / "a" / "dual.npz"
    dual = read_dual(good)
    # grid points on one sphere of the 1 x 2 x 4 domain's metric: x^2 + 4 y^2 + 16 z^2 = 324
    sphere = [(x, y, z) for x in range(-18, 19) for y in range(-9, 10) for z in range(-4, 5)
              if x * x + 4 * y * y + 16 * z * z == 324]
    sphere = sphere[:len(dual.grid_vertices)]
    assert len(sphere) == 65
    vertices = dual.grid_vertices.copy()
    vertices[:len(sphere)] = np.array(sphere) + [18, 9, 5]
    count = 30
    nodes = np.array([[v for v in range(65) if v != e] for e in range(count)])
    assert len({tuple(row) for row in nodes}) == count  # 30 distinct shapes of 64 co-spherical vertices
    _resigned(good, tmp_path / "hulls.npz", lambda m: m.update(grid=64),
              {"grid_vertices": vertices, "element_nodes": nodes, "element_sizes": np.full(count, 64),
               "element_circumcenter": np.zeros((count, 3))})
    measured = []
    real_measure = mesh_dual_module.measure
    monkeypatch.setattr(mesh_dual_module, "measure", lambda *args: measured.append(args) or real_measure(*args))
    capsys.readouterr()
    assert main(["check", str(tmp_path / "hulls.npz")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "member element_nodes: " in err and "Traceback" not in err, err
    assert measured == []



@pytest.mark.parametrize("replaced, tetrahedra", [
    # the attack: an interior cube of the hexahedra given as five of its Kuhn tetrahedra and one of
    # the other diagonal, which overlaps two of them and leaves a hole of its own volume
    ({3: KUHN[:5] + OTHER_DIAGONAL[:1]}, False),
    # the same in the conforming split into tetrahedra: nothing else is out of place
    ({5: KUHN[1:] + OTHER_DIAGONAL[1:2]}, True),
    # the overlap in one cube (a seventh tetrahedron), the hole in another (one of six missing)
    ({0: KUHN + OTHER_DIAGONAL[2:], 7: KUHN[:3] + KUHN[4:]}, True),
])
def test_a_resigned_dual_whose_elements_overlap_and_leave_a_hole_is_refused(tmp_path, capsys, replaced, tetrahedra):
    from cospherical.cli import main
    from cospherical.formats.dual import read_dual

    path = _forged_dual(tmp_path / "forged.npz", replaced, tetrahedra)
    dual = read_dual(path)
    assert dual.volume_sum() == 1 and dual.boundary_area_sums() == (2, 2, 2)  # every sum holds
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "forged.npz: member element_nodes: the elements are not a mesh" in err, err
    assert main(["check", str(_forged_dual(tmp_path / "good.npz", {}, tetrahedra))]) == 0  # unforged, it passes


@pytest.mark.parametrize("case", ["names with a newline and ESC", "names as paths", "two regions of one name",
                                  "two contacts of one name", "a region index true", "a part denominator of "
                                  "1000 digits", "a contact face repeated", "a contact face naming a vertex twice",
                                  "a million contact faces", "a contact box along another axis",
                                  "one quad over a whole contact", "a contact on a region it does not touch",
                                  "an element given the other region", "an interface of regions that do not exist",
                                  "an interface face naming a vertex twice"])
def test_a_forged_device_dual_is_refused_with_one_line(device_dual, tmp_path, capsys, case):
    # re-signed or consistently recomputed: a v4 file's names, contacts and parts are held to what the mesher
    # writes (names by the device file's rule; contact faces on elements of their region), never a traceback
    from cospherical.cli import main
    from cospherical.formats.dual import read_dual

    parts = read_dual(device_dual).regions
    faces, which = parts.contact_face_nodes, parts.contact_face_contact
    target = tmp_path / "forged.npz"
    manifest = {"names with a newline and ESC": {"region_names": ["si\n", "ox\x1b[2J"]},
                "names as paths": {"region_materials": ["../../etc/passwd", "<script>"]},
                "two regions of one name": {"region_names": ["si", "si"]},
                "two contacts of one name": {"contact_names": ["c", "c"]},
                "a region index true": {"contact_regions": [True, 1]},
                "a part denominator of 1000 digits": {"coupling_part_denominator": "9" * 1000},
                "an interface of regions that do not exist": {"interface_regions": [[0, 7]]},
                "a contact box along another axis": {"contact_boxes": [["1/7"] * 3 + ["1/7", "1", "1"],
                                                                       list(parts.contact_boxes[1])]}}
    repeated = faces.copy()
    repeated[0, 1] = repeated[0, 0]
    with np.load(device_dual) as archive:
        interface = archive["interface_face_nodes"].copy()
    interface[0, 1] = interface[0, 0]
    members = {"a contact face repeated": (np.concatenate([faces[:1], faces]), np.concatenate([which[:1], which])),
               "a contact face naming a vertex twice": (repeated, which),
               "a million contact faces": (np.repeat(faces[:1], 10**6, axis=0), np.repeat(which[:1], 10**6))}
    if case in manifest:
        _resigned(device_dual, target, lambda m: m.update(manifest[case]))
    elif case == "an interface face naming a vertex twice":
        _resigned(device_dual, target, members={"interface_face_nodes": interface})
    elif case in members:
        nodes, contact = members[case]
        _resigned(device_dual, target, members={"contact_face_nodes": nodes,
                                                "contact_face_contact": contact.astype(np.int32)})
    elif case == "one quad over a whole contact":
        grid_vertices = read_dual(device_dual).grid_vertices
        top = grid_vertices[:, 2].max()
        corners = [int(np.flatnonzero((grid_vertices == [0, y, z]).all(axis=1))[0])  # bulk: x = 0, z 0 .. 1/2
                   for y, z in ((0, 0), (top, 0), (top, top // 2), (0, top // 2))]
        keep = which != 0
        quad = np.full((1, faces.shape[1]), -1, dtype=faces.dtype)
        quad[0, :4] = corners
        _with_contact_faces(device_dual, target, np.concatenate([quad, faces[keep]]),
                            np.concatenate([[0], which[keep]]).astype(np.int32))
    elif case == "an element given the other region":  # an element with no contact face, said to be in the other
        dual = read_dual(device_dual)
        touching = [set(face[face >= 0].tolist()) for face in faces]
        inner = next(e for e, (row, size) in enumerate(zip(dual.element_nodes, dual.element_sizes))
                     if not any(face <= set(row[:size].tolist()) for face in touching))
        element_region = dual.regions.element_region.copy()
        element_region[inner] = 1 - element_region[inner]
        _with_contact_faces(device_dual, target, faces, which, element_region=element_region)
    else:  # the bulk contact (on si's side x = 0) said to be on ox
        _with_contact_faces(device_dual, target, faces, which, regions=(1, 0))
    capsys.readouterr()
    assert main(["check", str(target)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and err[:-1].isprintable() and len(err) < 400, err
    assert "\x1b" not in err and ("contact_face_nodes" in err or "manifest" in err or "element_region" in err
                                  or "interface_face_nodes" in err), err
    assert case != "one quad over a whole contact" or "is no face of an element of its region" in err, err
    assert case != "an element given the other region" or "member element_region" in err, err
    assert case != "a contact on a region it does not touch" or "is no face of an element of its region" in err \
        or "not on the boundary of region 'ox'" in err, err


def test_a_version_4_device_dual_is_still_read_and_checked(tmp_path, capsys):
    """Version 4 (before interfaces) counted a device's boundary in its bounding box's sides only: such a file
    is still read (no interfaces) and checked by that rule, and the version 5 file of the same L-shaped device
    holds its interfaces and the notch in its boundary."""
    from dataclasses import replace
    from fractions import Fraction as F

    from cospherical.api.mesh import build_mesh
    from cospherical.cli import main
    from cospherical.formats.dual import read_dual, write_dual
    from cospherical.formats.dual.verify import _Vertices
    from cospherical.mesh.device import Device, Region
    from cospherical.mesh.dual import mesh_dual

    def box(*values):
        return tuple(F(v) for v in values)

    device = Device("l", (Region("a", "Si", (box(0, 0, 0, 2, 1, 1),)), Region("b", "Ox", (box(0, 1, 0, 1, 2, 1),))),
                    (), (), 1)
    write_dual(build_mesh(device=device, uniform=False, dual=True).dual, tmp_path / "v5.npz")
    dual = read_dual(tmp_path / "v5.npz")
    assert dual.regions.interfaces.names == ("a|b",) and dual.regions.interfaces.areas() == [1]
    assert dual.boundary_area_sums() == (2, 2, F(3, 2))  # the notch's walls x = 1 and y = 1 too
    sides = mesh_dual(_Vertices(dual.box, dual.grid, dual.grid_vertices), (dual.element_nodes, dual.element_sizes))
    old = replace(dual, boundary=sides.boundary, boundary_area=sides.boundary_area,
                  boundary_area_exact=sides.boundary_area_exact,
                  boundary_area_denominator=sides.boundary_area_denominator,
                  regions=replace(dual.regions, interfaces=None))
    write_dual(old, tmp_path / "v4.npz")
    with np.load(tmp_path / "v4.npz") as archive:
        assert json.loads(archive["manifest"].tobytes())["version"] == 4 and "interface_part" not in archive.files
    again = read_dual(tmp_path / "v4.npz")
    assert again.regions.interfaces is None and again.boundary_area_sums() == (F(3, 2), F(3, 2), F(3, 2))
    capsys.readouterr()
    assert main(["check", str(tmp_path / "v4.npz")]) == 0 and main(["check", str(tmp_path / "v5.npz")]) == 0
    # a version 4 file with the union's boundary: not what version 4 means
    write_dual(replace(dual, regions=replace(dual.regions, interfaces=None)), tmp_path / "mixed.npz")
    assert main(["check", str(tmp_path / "mixed.npz")]) == 2
    assert "the boundary areas sum to 2, 2, 3/2" in capsys.readouterr().err
