"""``dual.npz``, the dual ``cospherical mesh --dual`` writes: deterministic, read back alike by meshio; truncated,
tampered, re-signed with hostile numbers or inflating files refused in one line."""

from __future__ import annotations

import json
import time
import warnings
from pathlib import Path

import numpy as np
import pytest


@pytest.fixture(scope="module")
def dual_run(tmp_path_factory):
    from cospherical.cli import main

    out = tmp_path_factory.mktemp("dual")
    argv = ["mesh", "--domain", "1", "2", "4", "--refine", "point:1/5,3/10,2/5", "--levels", "3", "--dual",
            "--no-uniform", "--format", "json", "--delaunay", "leaf"]
    assert main([*argv, "--out", str(out / "a")]) == 0
    assert main([*argv, "--out", str(out / "b")]) == 0
    return out


@pytest.mark.oracle_meshio
def test_mesh_dual_writes_a_deterministic_dual_npz_and_vtu_data(dual_run):
    import json
    import zipfile

    import meshio

    from cospherical.formats.dual import read_dual

    a, b = dual_run / "a", dual_run / "b"
    assert (a / "dual.npz").read_bytes() == (b / "dual.npz").read_bytes()
    with zipfile.ZipFile(a / "dual.npz") as archive:  # no clock, no umask in the file; every member deflated
        assert {(i.date_time, i.external_attr >> 16, i.compress_type) for i in archive.infolist()} == {
            ((1980, 1, 1, 0, 0, 0), 0o644, zipfile.ZIP_DEFLATED)}
    report = json.loads((a / "report.json").read_text())
    dual = read_dual(a / "dual.npz")
    assert dual.volume_sum() == 1 and len(dual.edges) == report["dual"]["edges"]
    # a 1 x 2 x 4 leaf mesh is not Delaunay: the report says so, the file keeps every edge
    assert report["negative_coefficients"] == dual.negative_coefficients().to_dict()
    assert report["negative_coefficients"]["interior"] > 0
    assert report["dual"]["mixed"]["nonzeros"] == dual.laplacian().nnz
    vtu = meshio.read(a / "mesh.vtu")
    assert np.array_equal(vtu.point_data["control_volume"], dual.control_volume)
    assert np.array_equal(vtu.point_data["boundary_area"], dual.boundary_area)
    assert dual.boundary_area_sums() == (2, 2, 2)  # read back: the exact areas and their factors
    ok = np.concatenate(vtu.cell_data["delaunay_ok"])
    assert (ok == 0).sum() == report["delaunay_violations"] > 0
    assert np.concatenate(vtu.cell_data["circumcenter"]).shape == (report["elements"], 3)


def test_a_truncated_or_tampered_dual_npz_is_refused_with_one_line(dual_run, tmp_path, capsys):
    import struct
    import zipfile

    from cospherical.cli import main

    good = (dual_run / "a" / "dual.npz").read_bytes()
    assert main(["check", str(dual_run / "a" / "dual.npz")]) == 0
    (tmp_path / "truncated.npz").write_bytes(good[: len(good) // 2])
    # a member rewritten with a valid zip CRC: only the manifest's checksum can tell
    with zipfile.ZipFile(dual_run / "a" / "dual.npz") as source, \
            zipfile.ZipFile(tmp_path / "tampered.npz", "w") as target:
        for info in source.infolist():
            data = source.read(info)
            if info.filename == "coefficient.npy":
                data = data[:-8] + np.float64(1e9).tobytes()
            target.writestr(info, data)
    flipped = bytearray(good)
    with zipfile.ZipFile(dual_run / "a" / "dual.npz") as source:  # a byte in the middle of a member's deflated data
        info = source.getinfo("edges.npy")
        name_length, extra_length = struct.unpack("<HH", good[info.header_offset + 26:info.header_offset + 30])
        start = info.header_offset + 30 + name_length + extra_length  # after its local header
    flipped[start + info.compress_size // 2] ^= 0xFF
    (tmp_path / "flipped.npz").write_bytes(bytes(flipped))
    (tmp_path / "empty.npz").write_bytes(b"")
    with zipfile.ZipFile(dual_run / "a" / "dual.npz") as source, \
            zipfile.ZipFile(tmp_path / "twice.npz", "w") as target, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # zipfile's "Duplicate name"
        edges = source.read("edges.npy")
        for info in source.infolist():
            target.writestr(info.filename, source.read(info))
        target.writestr("edges.npy", edges)  # a reader takes one of the two: which?
    capsys.readouterr()
    for name in ("truncated", "tampered", "flipped", "empty", "twice"):
        assert main(["check", str(tmp_path / f"{name}.npz")]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and f"{name}.npz" in err and "Traceback" not in err
    assert "member 'edges.npy' appears twice" in err


def _resigned(good: Path, target: Path, manifest_edit=None, members: dict | None = None) -> None:
    """A dual.npz whose manifest or members were rewritten and whose checksums were renewed to match:
    only the reader's own bounds can refuse it."""
    import hashlib
    import io
    import json
    import zipfile

    with zipfile.ZipFile(good) as source:
        blobs = {info.filename[:-4]: source.read(info) for info in source.infolist()}
    manifest = json.loads(np.lib.format.read_array(io.BytesIO(blobs.pop("manifest"))).tobytes().decode())
    for name, array in (members or {}).items():
        buffer = io.BytesIO()
        np.lib.format.write_array(buffer, array, allow_pickle=False)
        blobs[name] = buffer.getvalue()
    manifest["sha256"] = {name: hashlib.sha256(blob).hexdigest() for name, blob in blobs.items()}
    if manifest_edit:
        manifest = manifest_edit(manifest) or manifest
    buffer = io.BytesIO()
    text = manifest if isinstance(manifest, str) else json.dumps(manifest)  # an edit may give the text itself
    np.lib.format.write_array(buffer, np.frombuffer(text.encode(), dtype=np.uint8))
    with zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("manifest.npy", buffer.getvalue())
        for name, blob in blobs.items():
            archive.writestr(f"{name}.npy", blob)


@pytest.mark.parametrize("case", ["factor 1e999999999", "factor 1e400", "grid 10**400", "integers --5",
                                  "integers of 5000 digits", "boundary factors not the domain's",
                                  "manifest nested 100,000 deep", "manifest with a repeated key",
                                  "a grid vertex outside the grid", "version 2 (no elements)",
                                  "volume denominator of 1000 digits", "boundary denominator of 1000 digits",
                                  "version 3.0", "version 10**400"])
def test_a_resigned_dual_npz_with_hostile_numbers_is_one_line_at_once(dual_run, tmp_path, capsys, case):
    from cospherical.cli import main

    good = dual_run / "a" / "dual.npz"
    edits = {"factor 1e999999999": lambda m: m.update(volume_factor_squared="1e999999999"),
             "factor 1e400": lambda m: m.update(volume_factor_squared="1" + "0" * 400),
             "grid 10**400": lambda m: m.update(grid=10**400),
             "boundary factors not the domain's": lambda m: m.update(boundary_factors_squared=["1e400", "1", "1"]),
             # the manifest read by the readers' one JSON parser (json.loads recursed: a RecursionError
             # traceback), which also refuses a repeated key instead of keeping the last
             "manifest nested 100,000 deep": lambda m: "[" * 100_000 + "]" * 100_000,
             "manifest with a repeated key": lambda m: json.dumps(m)[:-1] + ', "version": 1}',
             "version 2 (no elements)": lambda m: m.update(version=2),
             "version 3.0": lambda m: m.update(version=3.0),  # a float: not what the writer writes
             "version 10**400": lambda m: m.update(version=10**400),
             # the sums they give are named, cut: not a line of a thousand digits
             "volume denominator of 1000 digits": lambda m: m.update(volume_denominator="9" * 1000),
             "boundary denominator of 1000 digits": lambda m: m.update(boundary_area_denominator="9" * 1000)}
    members = None
    if case.startswith("integers"):
        from cospherical.formats.dual import read_dual

        count = len(read_dual(good).volume_exact)
        members = {"volume_exact": np.array(["--5" if "--5" in case else "9" * 5000] * count)}
    if case == "a grid vertex outside the grid":  # re-signed: the checks' sums never read the vertices
        from cospherical.formats.dual import read_dual

        vertices = read_dual(good).grid_vertices.copy()
        vertices[0] = [-1, 10**15, 0]
        members = {"grid_vertices": vertices}
    _resigned(good, tmp_path / "hostile.npz", edits.get(case), members)
    capsys.readouterr()
    start = time.monotonic()
    assert main(["check", str(tmp_path / "hostile.npz")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and len(err) < 400, err
    assert time.monotonic() - start < 30  # 10**999999999 would take far longer
    assert case != "manifest with a repeated key" or "repeated key 'version'" in err, err
    assert not case.startswith("version 2") or "dual format version 2; this reads 3, 4 and 5 (write it again with " \
        "cospherical mesh --dual)" in err, err
    assert not case.startswith("version 3") or "dual format version 3.0; this reads" in err, err


def _edited(good: Path, target: Path, edit) -> None:
    """A re-signed copy of ``good`` whose members ``edit(arrays)`` changed in place (numpy arrays by name)."""
    import io
    import zipfile

    with zipfile.ZipFile(good) as source:
        arrays = {info.filename[:-4]: np.lib.format.read_array(io.BytesIO(source.read(info)))
                  for info in source.infolist() if info.filename != "manifest.npy"}
    changed = set(edit(arrays))
    _resigned(good, target, members={name: arrays[name] for name in changed})


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


def test_a_dual_npz_that_inflates_is_refused_from_its_headers(dual_run, tmp_path, capsys, monkeypatch):
    """A member whose header claims 100 MB of zeros (deflated to 100 KB, re-signed) is refused
    from the headers, before its data is read: the shapes disagree. Consistent claims beyond
    half the machine's memory are refused likewise (here the machine is made small)."""
    import hashlib
    import io
    import tracemalloc
    import zipfile

    from cospherical.cli import main
    from cospherical.formats import dual as dual_format

    good = dual_run / "a" / "dual.npz"
    bomb = tmp_path / "bomb.npz"
    count = 25 << 22  # 105 MB
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "|b1", "fortran_order": False, "shape": (count,)})
    digest = hashlib.sha256(header.getvalue())
    zeros = bytes(1 << 22)
    for _ in range(count // len(zeros)):
        digest.update(zeros)
    with zipfile.ZipFile(good) as source, zipfile.ZipFile(bomb, "w", zipfile.ZIP_DEFLATED, compresslevel=1) as out:
        for info in source.infolist():
            if info.filename == "boundary.npy":
                with out.open("boundary.npy", "w", force_zip64=True) as member:
                    member.write(header.getvalue())
                    for _ in range(count // len(zeros)):
                        member.write(zeros)
            elif info.filename == "manifest.npy":
                manifest = json.loads(np.lib.format.read_array(io.BytesIO(source.read(info))).tobytes())
                manifest["sha256"]["boundary"] = digest.hexdigest()  # re-signed: only the reader's bounds refuse it
                text = np.frombuffer(json.dumps(manifest).encode(), dtype=np.uint8)
                buffer = io.BytesIO()
                np.lib.format.write_array(buffer, text)
                out.writestr("manifest.npy", buffer.getvalue())
            else:
                out.writestr(info.filename, source.read(info))
    assert bomb.stat().st_size < 1 << 20
    capsys.readouterr()
    tracemalloc.start()
    try:
        assert main(["check", str(bomb)]) == 2
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"member boundary: bool ({count},), expected b (" in err, err
    assert peak < 20 * 2**20, peak  # it read the 100 MB (twice: the data and its array) before

    monkeypatch.setattr(dual_format, "machine_memory", lambda: 2 * good.stat().st_size)
    assert main(["check", str(good)]) == 2
    assert "more than half this machine's memory" in capsys.readouterr().err


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


# the cube's six Kuhn tetrahedra around its diagonal 0-6 (corners in VTK hexahedron order) and tetrahedra of the
# same volume (1/6 of the cube) around the other diagonals
KUHN = [[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]]
OTHER_DIAGONAL = [[1, 2, 3, 7], [4, 5, 7, 2], [3, 0, 1, 5]]


def _forged_dual(path: Path, replaced: dict[int, list[list[int]]], tetrahedra: bool = False) -> Path:
    """The dual.npz of the uniform 4 x 4 x 4 cube tree (64 hexahedra, or with ``tetrahedra`` their
    conforming split: each cube's six Kuhn tetrahedra) whose ``replaced`` interior cubes (k: the k-th
    interior one) are given instead as these tetrahedra (corners of the cube, VTK order), its dual
    computed from those elements and written as the mesher writes it: every value is its elements'."""
    from cospherical.core.configuration import Box
    from cospherical.formats.dual import write_dual
    from cospherical.mesh.assembly import assemble
    from cospherical.mesh.dual import mesh_dual
    from cospherical.mesh.octree import build_octree, parse_shape
    from cospherical.mesh.tetrahedra import split_tetrahedra

    mesh = assemble(build_octree(Box.parse(["1", "1", "1"]), 2, [parse_shape("point:0.5,0.5,0.5")]))
    conn, sizes = mesh.connectivity()
    inside = [e for e in range(len(mesh)) if ((mesh.tree.positions[mesh.element_leaf[e]] % 3) > 0).all()]
    assert len(mesh) == 64 and len(inside) == 8 and (sizes == 8).all()
    split = split_tetrahedra(mesh)
    rows = []
    for e in range(len(mesh)):
        own = [np.r_[t, [-1] * 4] for t in split.nodes[split.parent == e]] if tetrahedra else [conn[e]]
        if e in inside and inside.index(e) in replaced:
            if tetrahedra:  # the split is the Kuhn one: the forgery differs from it only where it says
                assert {frozenset(t[:4]) for t in own} == {frozenset(conn[e][k]) for k in KUHN}
            own = [np.r_[conn[e][t], [-1] * 4] for t in replaced[inside.index(e)]]
        rows += own
    nodes = np.array(rows, dtype=np.int32)
    write_dual(mesh_dual(mesh, (nodes, (nodes >= 0).sum(axis=1).astype(np.int8))), path)
    return path


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


@pytest.fixture(scope="module")
def device_dual(tmp_path_factory):
    """A small device's dual.npz (version 4): two regions, a contact on each, both on the side x = 0 (the
    elements at x = 1 have no contact face)."""
    from fractions import Fraction as F

    from cospherical.api.mesh import build_mesh
    from cospherical.mesh.device import Contact, Device, Region

    def box(*values):
        return tuple(F(v) for v in values)

    device = Device("two", (Region("si", "Si", (box(0, 0, 0, 1, 1, "1/2"),)),
                            Region("ox", "SiO2", (box(0, 0, "1/2", 1, 1, 1),))),
                    (Contact("bulk", "si", box(0, 0, 0, 0, 1, "1/2")), Contact("gate", "ox", box(0, 0, "1/2", 0, 1, 1))),
                    (), 1)
    path = tmp_path_factory.mktemp("device") / "dual.npz"
    from cospherical.formats.dual import write_dual

    write_dual(build_mesh(device=device, uniform=False, dual=True).dual, path)
    return path


def _with_contact_faces(good: Path, target: Path, faces: np.ndarray, which: np.ndarray, regions=None,
                        element_region=None) -> None:
    """The dual at ``good`` with other contact faces (and contact regions), its contact parts computed again
    from them by the library itself: consistent, so only the check of the faces themselves can refuse it."""
    from dataclasses import replace
    from fractions import Fraction

    from cospherical.formats.dual import read_dual, write_dual
    from cospherical.mesh.regions import region_parts

    dual = read_dual(good)
    parts = dual.regions
    regions = regions or parts.contact_regions
    contacts = tuple((name, region, box, next(a for a in range(3) if Fraction(box[a]) == Fraction(box[a + 3])))
                     for name, region, box in zip(parts.contact_names, regions, parts.contact_boxes))
    element_region = parts.element_region if element_region is None else element_region
    again = region_parts(dual.box, dual.grid, dual.grid_vertices, dual, element_region, parts.names,
                         parts.materials, contacts, faces, which, tuple(Fraction(t) for t in dual.box.texts),
                         parts.origin, boxes=parts.boxes)
    write_dual(replace(dual, regions=again), target)


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


def test_each_member_is_what_numpy_save_writes():
    """The writer makes each .npy itself (its header, then the array's own bytes): its bytes are numpy.save's, for
    every kind of member (ints, floats, bools, bytes, decimal text, empty, a non-contiguous view)."""
    import io

    from cospherical.formats.dual import _npy

    for array in (np.arange(10), np.zeros((5, 3)), np.array([], dtype=np.int64), np.zeros((0, 3)),
                  np.array(["12", "-3"], dtype="U200"), np.array([], dtype="U200"), np.frombuffer(b"{}", np.uint8),
                  np.ones((4, 3), dtype=bool), np.arange(6, dtype=np.int32).reshape(3, 2)[:, :1]):
        saved = io.BytesIO()
        np.save(saved, array, allow_pickle=False)
        header, data = _npy(array)
        assert header + bytes(data) == saved.getvalue()


def test_distinct_elements_are_proved_distinct_even_when_every_hash_collides(dual_run, monkeypatch):
    """Elements are proved pairwise different by one hash per element; equal hashes (here: all of them) send
    the proof to sorting the elements themselves, which finds them different, as they are."""
    from cospherical.formats.dual import read_dual
    from cospherical.mesh.dual import shapes

    good = dual_run / "a" / "dual.npz"
    monkeypatch.setattr(shapes, "_ROW_HASH", np.zeros_like(shapes._ROW_HASH))
    assert len(read_dual(good).element_sizes) > 1


def test_exact_values_wider_than_the_text_column_are_written_whole(tmp_path, capsys):
    """Lengths of 37-digit fractions make coefficients of about 220 digits: they were cut to 200 characters
    without a word, and check refused the mesher's own file.  Written whole, the file reads back as the dual
    it was made from and check recomputes every value."""
    from cospherical.cli import main
    from cospherical.formats.dual import read_dual

    lengths = ["1234567890123456789012345678901234567/9876543210987654321098765432109876543",
               "9876543210987654321098765432109876541/1234567890123456789012345678901234569",
               "1357913579135791357913579135791357913/2468024680246802468024680246802468029"]
    out = tmp_path / "wide"
    assert main(["mesh", "--domain", *lengths, "--levels", "1", "--refine", "point:0.1,0.1,0.1", "--dual",
                 "--no-uniform", "--out", str(out)]) == 0
    dual = read_dual(out / "dual.npz")
    assert dual.coefficient_exact.dtype == object and max(len(str(v)) for v in dual.coefficient_exact) > 200
    capsys.readouterr()
    assert main(["check", str(out / "dual.npz")]) == 0, capsys.readouterr().err


def test_a_version_4_device_dual_is_still_read_and_checked(tmp_path, capsys):
    """Version 4 (before interfaces) counted a device's boundary in its bounding box's sides only: such a file
    is still read (no interfaces) and checked by that rule, and the version 5 file of the same L-shaped device
    holds its interfaces and the notch in its boundary."""
    from dataclasses import replace
    from fractions import Fraction as F

    from cospherical.api.mesh import build_mesh
    from cospherical.cli import main
    from cospherical.formats.dual import _Vertices, read_dual, write_dual
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
