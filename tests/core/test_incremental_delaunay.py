"""The exact incremental Delaunay engine against the definition, the project's walk and Qhull merged exactly."""

from __future__ import annotations

from itertools import combinations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from oracle import oracle_cells
from scipy.spatial import ConvexHull

from cospherical.core.configuration import Box
from cospherical.core.delaunay import delaunay_cells
from cospherical.core.geometry import Frame
from cospherical.core.incremental_delaunay import delaunay_tetrahedra
from cospherical.errors import InputError
from cospherical.mesh.assembly import assemble
from cospherical.mesh.checks import grid_weights
from cospherical.mesh.octree import build_octree, parse_shape


def cells_of(points, weights) -> tuple[set[frozenset[int]], list]:
    """The engine's tetrahedra, grouped by exact circumcenter into cells (vertex sets); and the tetrahedra."""
    frame = Frame.build(dict(enumerate(points)), weights)
    tets = delaunay_tetrahedra(points, weights)
    groups: dict = {}
    for tet in tets:
        assert frame.orient(*tet) > 0
        groups.setdefault(frame.center(frame.sphere(*tet)), set()).update(tet)
    return {frozenset(g) for g in groups.values()}, tets


def cells_by_definition(points, weights) -> set[frozenset[int]]:
    """Every sphere through four points that holds none strictly inside: all points on it are one cell."""
    frame = Frame.build(dict(enumerate(points)), weights)
    cells = set()
    for quad in combinations(range(len(points)), 4):
        sphere = frame.sphere(*quad)
        if sphere is None:
            continue
        sides = [sphere.side(lifted) for lifted in frame.lifted]
        if min(sides) == 0:
            cells.add(frozenset(i for i, side in enumerate(sides) if side == 0))
    return cells


WEIGHTS = st.sampled_from([(1, 1, 1), (1, 4, 16), (1, 2, 2), (9, 1, 4), (2, 3, 5)])  # (1, 2, 2): a sqrt(2) box


@pytest.mark.oracle_qhull
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.tuples(*[st.integers(0, 3)] * 3), min_size=5, max_size=13, unique=True), WEIGHTS)
def test_cells_are_the_delaunay_cells_by_definition(points, weights):
    # a small grid: many co-spherical, coplanar and collinear points, the degenerate cases
    if all(Frame.build(dict(enumerate(points)), weights).orient(0, *q) == 0
           for q in combinations(range(1, len(points)), 3)):
        with pytest.raises(ValueError, match="coplanar"):
            delaunay_tetrahedra(points, weights)
        return
    cells, tets = cells_of(points, weights)
    assert cells == cells_by_definition(points, weights)
    # the tetrahedra tile the hull: their volumes add up to its volume (Qhull's, of these small integers)
    frame = Frame.build(dict(enumerate(points)), weights)
    assert sum(frame.orient(*tet) for tet in tets) == round(6 * ConvexHull(np.array(points, float)).volume)


def test_bad_input():
    cube = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    with pytest.raises(ValueError, match="coplanar"):
        delaunay_tetrahedra([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0), (2, 3, 0)], (1, 1, 1))
    with pytest.raises(ValueError, match="coincide"):
        delaunay_tetrahedra(cube + [(1, 0, 1)], (1, 1, 1))
    with pytest.raises(ValueError, match="four"):
        delaunay_tetrahedra(cube[:3], (1, 1, 1))


CUBE = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]


@pytest.mark.parametrize("weights", [(0, 1, 1), (1, -1, 1), (-1, -1, -1), (0, 0, 0), (1, 1, 0), (1.0, 1, 1),
                                     (1, 0.5, 1), (True, 1, 1), (np.float64(2), 1, 1), (1, 1), (1, 1, 1, 1), ("1", 1, 1)])
def test_weights_that_are_no_metric_are_refused_by_name(weights):
    # a zero or negative weight is no metric: (0, 0, 0) made every point 'coincide with a vertex',
    # (0, 1, 1) and (-1, 1, 1) gave tetrahedra of a meaningless sphere test
    with pytest.raises(InputError, match=r"^weights .*: three positive integers"):
        delaunay_tetrahedra(CUBE, weights)


@pytest.mark.parametrize("point", [(1, 1, 0.5), (0.9, 1, 1), (np.float64(1), 1, 1), (True, 1, 1), (1, 1), (1, 1, 1, 1),
                                   ("1", 1, 1)])
def test_coordinates_that_are_not_integers_are_refused_never_truncated(point):
    # int() truncated 0.5 to 0: the point moved without a word
    with pytest.raises(InputError, match=r"^point 8 .*: three integer grid coordinates"):
        delaunay_tetrahedra(CUBE + [point], (1, 1, 1))


def test_numpy_integers_and_positive_weights_are_accepted():
    tets = delaunay_tetrahedra(np.array(CUBE + [(2, 1, 1)], dtype=np.int32), np.array([1, 4, 9], dtype=np.uint8))
    assert sorted(set().union(*tets)) == list(range(9))


@pytest.mark.oracle_qhull
@pytest.mark.parametrize("domain, levels, shape", [
    (["1", "2", "4"], 3, "sphere:0.5,1,2,0.6"),
    (["1", "1", "4"], 3, "point:0.2,0.7,3.1"),
    (["1", "sqrt(2)", "sqrt(2)"], 3, "box:0.1,0.2,0.3,0.4,0.5,0.6"),
])
def test_octree_vertices_equal_qhull_merged_exactly(domain, levels, shape):
    leaf = assemble(build_octree(Box.parse(domain), levels, [parse_shape(shape)], "vertex"))
    points = [tuple(int(x) for x in v) for v in leaf.vertices]
    assert cells_of(points, grid_weights(leaf))[0] == oracle_cells(leaf)


@pytest.mark.parametrize("domain", [["1e-12", "1", "3e9"], ["sqrt(2)", "1e-12", "1"]])
def test_extreme_boxes_equal_the_projects_walk(domain):
    # Qhull cannot triangulate these in floats; the project's exact walk (another algorithm) can, slowly
    box = Box.parse(domain)
    leaf = assemble(build_octree(box, 3, [parse_shape("point:0,0,0")], "vertex"))
    points = [tuple(int(x) for x in v) for v in leaf.vertices]
    weights = grid_weights(leaf)
    walk = {frozenset(cell.nodes) for cell in delaunay_cells(Frame.build(dict(enumerate(points)), weights))}
    assert cells_of(points, weights)[0] == walk
    assert len(walk) > 1


def test_the_walks_guard_finds_what_the_walk_finds():
    # the scan that bounds the walk: a finite tetrahedron holding the point, or a hull face it is beyond
    from cospherical.core.incremental_delaunay import _Triangulation

    cube = [(x, y, z) for x in (0, 2) for y in (0, 2) for z in (0, 2)]
    for point, infinite in (((1, 1, 1), False), ((2, 1, 1), False), ((5, 1, 1), True)):
        points = cube + [point]
        triangulation = _Triangulation(Frame.build(dict(enumerate(points)), (1, 1, 1)))
        triangulation.run(list(range(8)))
        t = triangulation._scan(8)
        assert (-1 in triangulation.vertices[t]) == infinite and triangulation._conflict(t, 8)
        assert cells_of(points, (1, 1, 1))[0] == cells_by_definition(points, (1, 1, 1))
