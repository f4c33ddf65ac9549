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
