"""Polyhedra of a tessellation: face kinds decided exactly, volume, circumcenter, counts, against independent oracles."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull

from cospherical import Box, Configuration
from cospherical.core.delaunay import delaunay_cells
from cospherical.core.geometry import Frame
from cospherical.core.polyhedron import face_kind, measure, polyhedron

HALF = Fraction(1, 2)
DIAMOND = {0: (HALF, 0, 0), 1: (1, HALF, 0), 2: (HALF, 1, 0), 3: (0, HALF, 0)}  # a square's midpoints


@pytest.mark.parametrize("lengths, kind", [((1, 1, 1), "rectangle"), ((1, 2, 1), "quadrilateral"),
                                           (("sqrt(2)", "sqrt(2)", 1), "rectangle")])
def test_a_four_gon_is_a_rectangle_only_where_the_box_makes_its_angles_right(lengths, kind):
    # The midpoints of a rectangle's sides make a rhombus: a square exactly when the rectangle is one.
    frame = Frame.build(DIAMOND, Box.parse([str(x) for x in lengths]).squared)
    assert face_kind(frame, (0, 1, 2, 3)) == kind


def test_other_polygons_are_named_by_their_sides():
    frame = Frame.build({i: (i, 0, 0) for i in range(9)}, (1, 1, 1))  # face_kind reads only the cycle's length
    assert [face_kind(frame, tuple(range(n))) for n in (3, 5, 6, 9)] == ["triangle", "pentagon", "hexagon", "9-gon"]
    trapezoid = Frame.build({0: (0, 0, 0), 1: (1, 0, 0), 2: (HALF, 1, 0), 3: (0, 1, 0)}, (1, 1, 1))
    assert face_kind(trapezoid, (0, 1, 2, 3)) == "quadrilateral"


def test_the_empty_box_is_one_cuboid():
    configuration = Configuration.from_code("000000000000", ["1", "2", "4"])
    frame = Frame.build(configuration.nodes(), configuration.box.squared)
    (cell,) = delaunay_cells(frame)
    poly = polyhedron(frame, cell)
    assert poly.counts == (8, 12, 6) and set(poly.face_kinds) == {"rectangle"}
    assert poly.unit_volume == 1 and poly.center == (HALF, HALF, HALF)
    assert poly.center_in_box(closed=True) and poly.center_in_box(closed=False)


def _circumcenter(points: list[tuple[Fraction, ...]]) -> tuple[Fraction, ...]:
    """The center equidistant from the points, by Gaussian elimination in fractions (an oracle of our own hand)."""
    p0 = points[0]
    rows = [[2 * (a - b) for a, b in zip(p, p0)] + [sum(a * a for a in p) - sum(b * b for b in p0)] for p in points[1:]]
    system = []
    for row in rows:  # keep three independent equations
        for pivot_row in system:
            col = next(i for i, x in enumerate(pivot_row[:3]) if x)
            row = [x - row[col] / pivot_row[col] * y for x, y in zip(row, pivot_row)]
        if any(row[:3]):
            system.append(row)
    assert len(system) == 3
    center = [Fraction(0)] * 3
    for row in reversed(system):
        col = next(i for i, x in enumerate(row[:3]) if x)
        center[col] = (row[3] - sum(row[i] * center[i] for i in range(3) if i != col)) / row[col]
    return tuple(center)


BOX = Box.parse(["1", "2", "4"])
SCALE = (1, 2, 4)


@settings(max_examples=12, deadline=None)
@given(st.lists(st.sampled_from("08"), min_size=12, max_size=12).map("".join))
def test_cells_measured_against_qhull_and_a_hand_solved_center(code):
    configuration = Configuration.from_code(code, BOX)
    nodes = configuration.nodes()
    frame = Frame.build(nodes, BOX.squared)
    polys = [polyhedron(frame, cell) for cell in delaunay_cells(frame)]
    assert sum(p.unit_volume for p in polys) == 1  # they tile the box, exactly
    index = {node: i for i, node in enumerate(frame.ids)}
    for poly in polys:
        vertices, edges, faces = poly.counts
        assert vertices - edges + faces == 2  # Euler: a convex polyhedron
        assert sum(len(f) for f in poly.faces) == 2 * edges and len(poly.face_kinds) == faces
        real = [tuple(Fraction(x) * s for x, s in zip(nodes[n], SCALE)) for n in poly.nodes]
        hull = ConvexHull(np.array(real, dtype=float))
        assert hull.volume == pytest.approx(float(poly.unit_volume) * 8, rel=1e-12)
        assert len(hull.vertices) == vertices  # every node is a vertex of its cell
        center = _circumcenter(real)
        assert tuple(c / s for c, s in zip(center, SCALE)) == poly.center
        inside = [all(0 <= c <= s for c, s in zip(center, SCALE)), all(0 < c < s for c, s in zip(center, SCALE))]
        assert [poly.center_in_box(closed=True), poly.center_in_box(closed=False)] == inside
        # measure() of the node list is the same element: the one place meshes and checks measure from
        measured = measure(frame, [index[n] for n in poly.nodes])
        assert measured.unit_volume == poly.unit_volume and measured.center == poly.center
        assert len(measured.cycles) == faces


def test_flat_or_scattered_nodes_have_no_volume_or_no_sphere():
    frame = Frame.build({0: (0, 0, 0), 1: (1, 0, 0), 2: (1, 1, 0), 3: (0, 1, 0), 4: (HALF, HALF, 1)}, (1, 1, 1))
    flat = measure(frame, [0, 1, 2, 3])
    assert flat.cycles == () and flat.unit_volume == 0 and flat.sphere is None and flat.center is None
    # a square pyramid is co-spherical: z^2 + 1/2 = (1 - z)^2 puts the center at height 1/4
    pyramid = measure(frame, [0, 1, 2, 3, 4])
    assert pyramid.unit_volume == Fraction(1, 3) and len(pyramid.cycles) == 5
    assert pyramid.center == (HALF, HALF, Fraction(1, 4))
    # a prism with one short edge: five corners on the sphere centered at (1/2, 1/2, 1/2), the sixth inside it
    prism = Frame.build({0: (0, 0, 0), 1: (1, 0, 0), 2: (0, 1, 0), 3: (0, 0, 1), 4: (1, 0, 1), 5: (0, 1, HALF)},
                        (1, 1, 1))
    scattered = measure(prism, range(6))
    assert scattered.sphere is None and scattered.center is None
    assert scattered.unit_volume == Fraction(1, 2) - Fraction(1, 12) and len(scattered.cycles) == 5
