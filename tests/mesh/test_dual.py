"""The finite-volume dual: exact identities on random octrees, and voro++ on the same vertices."""

from __future__ import annotations

from fractions import Fraction

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
