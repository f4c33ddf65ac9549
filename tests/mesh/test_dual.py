"""The finite-volume dual: exact identities on random octrees, and voro++ on the same vertices."""

from __future__ import annotations

import json
import time
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cospherical.core.configuration import Box
from cospherical.mesh.assembly import assemble
from cospherical.mesh.dual import mesh_dual
from cospherical.mesh.octree import build_octree, leaves_octree, parse_shape

CACHES: dict = {}  # per box, tessellations shared by the examples (the cache is keyed by code only)
BOXES = [["1", "1", "1"], ["1", "2", "4"], ["3/2", "1", "1"], ["1", "sqrt(2)", "sqrt(2)"]]


@st.composite
def octrees(draw):
    box = Box.parse(draw(st.sampled_from(BOXES)))
    levels = draw(st.integers(1, 3))
    coordinate = st.fractions(0, 1, max_denominator=9)
    points = draw(st.lists(st.tuples(coordinate, coordinate, coordinate), min_size=1, max_size=3))
    shapes = [parse_shape("point:" + ",".join(f"{x.numerator}/{x.denominator}" for x in p)) for p in points]
    return assemble(build_octree(box, levels, shapes), cache=CACHES.setdefault(box.texts, {}))


def exact_edge_terms(dual):
    """Per edge: its coefficient and its squared length as exact fractions (in the dual's common units)."""
    squared = dual.box.squared
    g = dual.grid_vertices.astype(object)
    delta = g[dual.edges[:, 1]] - g[dual.edges[:, 0]]
    length2 = [sum(w * int(d) ** 2 for w, d in zip(squared, row)) for row in delta]
    coef = [Fraction(int(c), dual.coefficient_denominator) for c in dual.coefficient_exact]
    return delta, coef, length2


PROPERTY = settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@PROPERTY
@given(octrees())
def test_volumes_sum_to_the_domain_exactly(mesh):
    dual = mesh_dual(mesh)
    assert dual.volume_sum() == 1
    assert np.isclose(dual.control_volume.sum(), np.prod(mesh.box.to_float()), rtol=1e-12)


@PROPERTY
@given(octrees())
def test_linear_functions_have_zero_discrete_laplacian_exactly(mesh):
    """At every interior vertex the sum of coefficient * (x_j - x_i) is the zero vector, exactly."""
    dual = mesh_dual(mesh)
    delta, _, _ = exact_edge_terms(dual)
    c = dual.coefficient_exact.astype(object)[:, None]
    total = np.zeros((len(dual.vertices), 3), dtype=object)
    np.add.at(total, dual.edges[:, 0], c * delta)
    np.add.at(total, dual.edges[:, 1], -c * delta)
    interior = ~dual.boundary
    assert interior.any() or len(mesh.tree) < 64
    assert all(x == 0 for x in total[interior].reshape(-1))
    # and the matrix: symmetric, zero row sums, its quadratic form zero on a linear function
    k = dual.laplacian()
    assert abs(k - k.T).max() == 0
    assert np.abs(k.sum(axis=1)).max() <= 1e-12 * np.abs(dual.coefficient).max()
    linear = dual.vertices @ np.array([0.3, -1.0, 2.0])
    assert np.abs((k @ linear)[interior]).max() <= 1e-11 * np.abs(dual.coefficient).max()


@PROPERTY
@given(octrees())
def test_area_times_length_is_six_volumes_exactly(mesh):
    dual = mesh_dual(mesh)
    _, coef, length2 = exact_edge_terms(dual)
    six = [Fraction(0)] * len(dual.vertices)
    for (i, j), c, l2 in zip(dual.edges.tolist(), coef, length2):
        six[i] += c * l2
        six[j] += c * l2
    # the coefficient's denominator carries one grid factor, a squared length two, a volume three
    grid = dual.grid
    volumes = [Fraction(int(v), dual.volume_denominator) for v in dual.volume_exact]
    assert all(s / grid ** 2 == 6 * v for s, v in zip(six, volumes))


@PROPERTY
@given(octrees())
def test_boundary_areas_sum_to_each_side_of_the_domain_exactly(mesh):
    """Per axis, the exact boundary areas of the vertices in each of the two sides normal to it sum to that side."""
    dual = mesh_dual(mesh)
    g, exact, den = dual.grid_vertices, dual.boundary_area_exact.astype(object), dual.boundary_area_denominator
    for k in range(3):
        low, high = g[:, k] == 0, g[:, k] == dual.grid
        assert sum(exact[low, k]) == den and sum(exact[high, k]) == den  # each side: one side's area
        assert all(x == 0 for x in exact[~(low | high), k])
    assert dual.boundary_area_sums() == (2, 2, 2)
    assert not np.any(dual.boundary_area[~dual.boundary])
    a, b, c = mesh.box.to_float()
    assert np.isclose(dual.boundary_area.sum(), 2 * (a * b + b * c + c * a), rtol=1e-12)


def reference_sums(mesh):
    """Every leaf element's exact pieces summed edge by edge and vertex by vertex in Fractions, one leaf at a time:
    no grouping, packing or sorting (what mesh_dual does in bulk)."""
    from cospherical.mesh.dual import element_pieces

    squared = tuple(Fraction(x) for x in mesh.box.squared)
    coefficients, volumes = {}, {}
    sizes = mesh.leaf_size()
    for _, pattern, leaves in mesh.groups():
        nodes = pattern.configuration.nodes()
        pieces = [element_pieces({n: nodes[n] for n in e.nodes}, e.faces, e.center, squared)
                  for e in pattern.elements]
        for leaf in leaves.tolist():
            ids, size = mesh.slots[leaf].tolist(), int(sizes[leaf])
            for piece in pieces:
                for (u, v), q in piece.edges.items():
                    key = tuple(sorted((ids[u], ids[v])))
                    coefficients[key] = coefficients.get(key, 0) + q * size
                for u, q in piece.volumes.items():
                    volumes[ids[u]] = volumes.get(ids[u], 0) + q * size ** 3
    return coefficients, volumes


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(octrees(), st.booleans())
def test_bulk_sums_equal_leaf_by_leaf_sums_exactly(mesh, packed):
    """The sorted bulk sums (key and payload packed in one int64, or argsorted apart) are the leaf-by-leaf sums."""
    from cospherical.mesh import dual as module

    saved = module.PACKED_BITS
    module.PACKED_BITS = saved if packed else 0  # 0: nothing fits, the argsort path
    try:
        dual = mesh_dual(mesh)
    finally:
        module.PACKED_BITS = saved
    coefficients, volumes = reference_sums(mesh)
    assert list(map(tuple, dual.edges.tolist())) == sorted(coefficients)
    grid = Fraction(dual.grid)
    assert [Fraction(int(c), dual.coefficient_denominator) * grid for c in dual.coefficient_exact] == [
        coefficients[key] for key in sorted(coefficients)]
    assert [Fraction(int(v), dual.volume_denominator) * grid ** 3 for v in dual.volume_exact] == [
        volumes[n] for n in range(len(dual.vertices))]


def test_element_list_path_equals_the_configuration_path():
    """The connectivity path (any element list) gives the leaf path's numbers, exactly."""
    box = Box.parse(["1", "2", "4"])
    mesh = assemble(build_octree(box, 2, [parse_shape("point:1/3,1/5,1/7")]),
                    cache=CACHES.setdefault(box.texts, {}))
    fast, generic = mesh_dual(mesh), mesh_dual(mesh, mesh.connectivity())
    assert np.array_equal(fast.edges, generic.edges)
    assert all(Fraction(int(x), fast.coefficient_denominator) == Fraction(int(y), generic.coefficient_denominator)
               for x, y in zip(fast.coefficient_exact, generic.coefficient_exact))
    assert all(Fraction(int(x), fast.volume_denominator) == Fraction(int(y), generic.volume_denominator)
               for x, y in zip(fast.volume_exact, generic.volume_exact))
    assert all(Fraction(int(x), fast.boundary_area_denominator) == Fraction(int(y), generic.boundary_area_denominator)
               for x, y in zip(fast.boundary_area_exact.reshape(-1), generic.boundary_area_exact.reshape(-1)))
    assert np.array_equal(fast.element_circumcenter, generic.element_circumcenter)


def test_a_non_delaunay_mesh_shows_its_negative_coefficients():
    """1 x 2 x 4 octrees are not globally Delaunay: the coefficients say so, nothing is clipped."""
    box = Box.parse(["1", "2", "4"])
    mesh = assemble(build_octree(box, 3, [parse_shape("point:1/5,3/10,2/5")]),
                    cache=CACHES.setdefault(box.texts, {}))
    dual = mesh_dual(mesh)
    negative = dual.negative_coefficients()
    assert negative["interior"] > 0
    assert negative["interior"] + negative["boundary"] == int((dual.coefficient < 0).sum())
    assert dual.volume_sum() == 1


# ---- voro++ on the same vertices ------------------------------------------------------------------


def discretize_leaves(levels: int, refine) -> tuple[list[int], list[tuple[int, int, int]]]:
    """Leaves of a discretize.TreeMesh on the unit cube (diagonal balance: our vertex balance)."""
    import discretize

    n = 2 ** levels
    tree = discretize.TreeMesh([[(1 / n, n)]] * 3, diagonal_balance=True)
    refine(tree)
    h = tree.h_gridded[:, 0]
    cell_levels = np.rint(np.log2(1 / h)).astype(int)
    corner = tree.cell_centers - h[:, None] / 2
    positions = np.rint(corner / h[:, None]).astype(int)
    return cell_levels.tolist(), [tuple(p) for p in positions.tolist()]


def voronoi(dual):
    """voro++ cells of the dual's vertices in the domain box: volumes and the face areas between vertex pairs."""
    import pyvoro

    lengths = dual.box.to_float()
    # voro++ leaves out points on a container's upper walls: widen it by one float step
    cells = pyvoro.compute_voronoi(dual.vertices.tolist(), [[0.0, np.nextafter(x, 2 * x)] for x in lengths],
                                   float(np.max(lengths)) / 8)
    volumes = np.array([cell["volume"] for cell in cells])
    faces = {}
    for i, cell in enumerate(cells):
        points = np.array(cell["vertices"])
        for face in cell["faces"]:
            j = face["adjacent_cell"]
            if j <= i:
                continue  # walls (negative) and the pair seen from the other side
            p = points[face["vertices"]]
            area = np.linalg.norm(np.cross(p[1:-1] - p[0], p[2:] - p[0]).sum(axis=0)) / 2
            faces[i, j] = faces.get((i, j), 0.0) + area
    return volumes, faces


def voro_agreement(mesh) -> float:
    dual = mesh_dual(mesh)
    volumes, faces = voronoi(dual)
    scale = np.prod(dual.box.to_float()) ** (1 / 3) / 2 ** mesh.tree.depth  # the finest leaf's size
    relative_volume = np.abs(volumes - dual.control_volume) / dual.control_volume
    ours = dict(zip(map(tuple, dual.edges.tolist()), dual.area.tolist()))
    real = {pair for pair, area in faces.items() if area > 1e-9 * scale ** 2}
    assert set(ours) == real, "mesh edges are not the pairs with a Voronoi face of positive area"
    relative_area = max(abs(faces[pair] - area) / area for pair, area in ours.items())
    return max(float(relative_volume.max()), relative_area)


OCTREES = {
    "discretize ball": lambda: leaves_octree(Box.parse(["1", "1", "1"]), *discretize_leaves(
        4, lambda t: t.refine_ball([0.4, 0.55, 0.5], 0.2, 4))),
    "discretize points": lambda: leaves_octree(Box.parse(["1", "1", "1"]), *discretize_leaves(
        4, lambda t: t.insert_cells(np.random.default_rng(7).random((4, 3)), [4] * 4))),
    "sphere": lambda: build_octree(Box.parse(["1", "1", "1"]), 3, [parse_shape("sphere:0.5,0.5,0.5,0.3")]),
    "plane": lambda: build_octree(Box.parse(["1", "1", "1"]), 3, [parse_shape("plane:1,2,3,2.1")]),
    "point": lambda: build_octree(Box.parse(["2", "2", "2"]), 4, [parse_shape("point:0.3,0.7,0.1")]),
    "random points": lambda: build_octree(Box.parse(["1", "1", "1"]), 4, [
        parse_shape("point:" + ",".join(str(x) for x in p)) for p in np.round(
            np.random.default_rng(3).random((3, 3)), 3).tolist()]),
}


@pytest.mark.oracle_voro
@pytest.mark.oracle_discretize
@pytest.mark.parametrize("name", sorted(OCTREES))
def test_control_volumes_and_face_areas_are_voro_plus_plus_cells(name):
    """On cube octrees the dual is the Voronoi diagram clipped to the domain: voro++ agrees to 1e-12."""
    tree = OCTREES[name]()
    assert voro_agreement(assemble(tree, cache=CACHES.setdefault(tree.box.texts, {}))) <= 1e-12


# ---- cospherical mesh --dual and dual.npz ----------------------------------------------------------


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

    import meshio

    from cospherical.formats.dual import read_dual

    a, b = dual_run / "a", dual_run / "b"
    assert (a / "dual.npz").read_bytes() == (b / "dual.npz").read_bytes()
    report = json.loads((a / "report.json").read_text())
    dual = read_dual(a / "dual.npz")
    assert dual.volume_sum() == 1 and len(dual.edges) == report["dual"]["edges"]
    # a 1 x 2 x 4 leaf mesh is not Delaunay: the report says so, the file keeps every edge
    assert report["negative_coefficients"] == dual.negative_coefficients()
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
    flipped[len(good) // 3] ^= 0xFF
    (tmp_path / "flipped.npz").write_bytes(bytes(flipped))
    (tmp_path / "empty.npz").write_bytes(b"")
    capsys.readouterr()
    for name in ("truncated", "tampered", "flipped", "empty"):
        assert main(["check", str(tmp_path / f"{name}.npz")]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and f"{name}.npz" in err and "Traceback" not in err


def test_a_full_disk_under_tetgens_scratch_file_names_that_file(monkeypatch):
    # a failed write names no file (EFBIG from a file-size limit was 'cospherical: error: File too large')
    import errno

    from cospherical.mesh.dual import delaunay_tetrahedra

    def full(*args, **kwargs):
        raise OSError(errno.EFBIG, "File too large")
    monkeypatch.setattr(np, "savetxt", full)
    with pytest.raises(OSError) as raised:
        delaunay_tetrahedra(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]))
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

    from cospherical.mesh.dual import delaunay_tetrahedra

    assert shutil.which("tetgen"), "tetgen (Debian) is a test dependency: scripts/setup.sh installs it"
    tree = OCTREES[name]()
    mesh = assemble(tree, cache=CACHES.setdefault(tree.box.texts, {}))
    mixed = mesh_dual(mesh)
    tets, tool, flat = delaunay_tetrahedra(mesh.vertices)
    assert tool == "tetgen" and flat == 0
    tetra = mesh_dual(mesh, (tets.astype(np.int32), np.full(len(tets), 4, dtype=np.int8)))

    def exact(values, denominator):
        return [Fraction(int(v), denominator) for v in values]

    assert exact(tetra.volume_exact, tetra.volume_denominator) == exact(mixed.volume_exact, mixed.volume_denominator)
    ours = dict(zip(map(tuple, mixed.edges.tolist()), exact(mixed.coefficient_exact, mixed.coefficient_denominator)))
    theirs = dict(zip(map(tuple, tetra.edges.tolist()), exact(tetra.coefficient_exact, tetra.coefficient_denominator)))
    assert set(ours) <= set(theirs) and len(theirs) > len(ours)
    assert all(theirs[pair] == ours.get(pair, 0) for pair in theirs)


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
                                  "a grid vertex outside the grid"])
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
             "manifest with a repeated key": lambda m: json.dumps(m)[:-1] + ', "version": 1}'}
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
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert time.monotonic() - start < 30  # 10**999999999 would take far longer
    assert case != "manifest with a repeated key" or "repeated key 'version'" in err, err


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

    i, j = dual.edges[min(a, b)]
    for edit, needle in ((balanced_coefficients, f"member coefficient_exact: edge {i}-{j} "),
                         (balanced_volumes, "member volume_exact: vertex 0 "),
                         (a_float_alone, f"member coefficient: edge {dual.edges[b, 0]}-{dual.edges[b, 1]} "),
                         (a_vertex_twice, "member element_nodes: element 2 names a vertex twice")):
        target = tmp_path / f"{edit.__name__}.npz"
        _edited(good, target, edit)
        if edit is not a_vertex_twice:  # the reader refuses that one itself
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


@pytest.mark.parametrize("domain", [["1e-12", "1e-12", "1e-12"], ["1e-12", "1", "1"], ["3e9", "1", "1"]])
def test_the_dual_of_tiny_and_huge_domains_is_exact(domain, tmp_path):
    from cospherical.formats.dual import read_dual, write_dual

    box = Box.parse(domain)
    dual = mesh_dual(assemble(build_octree(box, 2, [parse_shape("point:0,0,0")])))
    assert dual.volume_sum() == 1  # the control volumes fill the domain, as a fraction of its volume
    assert dual.boundary_area_sums() == (2, 2, 2)  # and the boundary areas its surface
    assert dual.negative_coefficients()["interior"] == 0
    write_dual(dual, tmp_path / "dual.npz")  # integers too wide for int64 go as decimal text, and come back
    again = read_dual(tmp_path / "dual.npz")
    for name in ("coefficient_exact", "volume_exact", "boundary_area_exact"):
        assert getattr(again, name).tolist() == getattr(dual, name).tolist()
