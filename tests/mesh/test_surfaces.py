"""Each vertex's part of flat faces (a device's boundary and interfaces), exactly."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from cospherical import build_mesh
from cospherical.errors import InputError
from cospherical.mesh.surfaces import face_parts, polygon_parts, vertex_parts


@st.composite
def flat_faces(draw):
    """A triangle or an axis-aligned rectangle on the grid, in a coordinate plane, at an offset, any orientation."""
    axis = draw(st.integers(0, 2))
    coordinates = st.integers(0, 12)
    if draw(st.booleans()):
        corners = [(draw(coordinates), draw(coordinates)) for _ in range(3)]
        (x0, y0), (x1, y1), (x2, y2) = corners
        if (x1 - x0) * (y2 - y0) == (x2 - x0) * (y1 - y0):  # on one line: no circle
            corners = [(0, 0), (3, 0), (0, 2)]
    else:
        x, y = draw(coordinates), draw(coordinates)
        w, h = draw(st.integers(1, 6)), draw(st.integers(1, 6))
        corners = [(x, y), (x + w, y), (x + w, y + h), (x, y + h)]
    if draw(st.booleans()):
        corners = corners[::-1]
    level = draw(st.integers(0, 12))
    points = []
    for b, d in corners:
        point = [level, level, level]
        point[(axis + 1) % 3], point[(axis + 2) % 3] = b, d
        points.append(point)
    return axis, corners, np.array(points, dtype=np.int64)


@settings(max_examples=40, deadline=None)
@given(flat_faces())
def test_a_faces_parts_sum_to_its_area_and_scale_as_its_square(face):
    axis, corners, points = face
    nodes = np.arange(len(points))[None, :]
    axes, numerators, denominator = face_parts(points, nodes, (1, 1, 1))
    twice = abs(sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(corners, corners[1:] + corners[:1])))
    assert axes.tolist() == [axis]
    assert Fraction(int(numerators.sum()), denominator) == Fraction(twice, 2)
    # a rectangle splits into four equal quarters (its circle centre is its centre)
    if len(corners) == 4:
        assert len(set(numerators[0].tolist())) == 1
    # moved and doubled: the same parts, times four
    _, doubled, over = face_parts(2 * points + 6, nodes, (1, 1, 1))
    assert [Fraction(int(v), over) for v in doubled[0]] == [4 * Fraction(int(v), denominator) for v in numerators[0]]
    # in device units, a grid of 12 steps over lengths 3, 5, 7 (steps of three lengths: the circle is the real
    # one, not the grid's): the parts of the polygon drawn in real coordinates
    lengths = (Fraction(3), Fraction(5), Fraction(7))
    vertex, which, exact, common = vertex_parts(points, nodes, np.array([0]), 1, 12, lengths)
    scale = (lengths[(axis + 1) % 3] / 12, lengths[(axis + 2) % 3] / 12)
    real = polygon_parts([(Fraction(x) * scale[0], Fraction(y) * scale[1]) for x, y in corners])
    assert vertex.tolist() == list(range(len(points))) and which.tolist() == [0] * len(points)
    assert [Fraction(int(v), common) for v in exact] == real


def test_a_face_off_the_coordinate_planes_is_refused():
    points = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 1]])
    with pytest.raises(InputError, match="not flat in a coordinate plane"):
        face_parts(points, np.array([[0, 1, 2]]), (1, 1, 1))


def test_a_one_box_devices_boundary_is_the_boxs_exactly(tmp_path):
    """The true boundary's figures (from the faces met once) are the dual's element-by-element ones (the box's
    sides) on a device of one box, vertex by vertex and axis by axis, exactly; and an interface's parts sum
    to its area vertex by vertex from either side (the plane z = 1 of a 1 x 2 x 2 stack)."""
    from cospherical.mesh.dual import mesh_dual

    path = tmp_path / "stack.yaml"
    path.write_text("device: stack\nregions:\n  - {name: a, material: Si, boxes: [[0, 0, 0, 1, 2, 1]]}\n"
                    "  - {name: b, material: Ox, boxes: [[0, 0, 1, 1, 2, 2]]}\n"
                    "refine: [{point: [0.3, 0.6, 1.2]}]\nlevels: 2\n")
    m = build_mesh(device=path, uniform=False, dual=True)
    dual, box = m.dual, mesh_dual(m.assembled)  # the box's sides: the one-box rule, element by element
    assert dual.boundary_edge is not None and box.boundary_edge is None
    assert np.array_equal(dual.boundary, box.boundary)
    for k in range(3):
        assert [Fraction(int(x), dual.boundary_area_denominator) for x in dual.boundary_area_exact[:, k]] == \
            [Fraction(int(x), box.boundary_area_denominator) for x in box.boundary_area_exact[:, k]]
    assert dual.negative_coefficients() == box.negative_coefficients()
    interfaces = dual.regions.interfaces
    assert interfaces.names == ("a|b",) and interfaces.areas() == [2]
    on = np.unique(interfaces.face_nodes[interfaces.face_nodes >= 0])
    assert np.array_equal(interfaces.vertex, on) and np.all(dual.grid_vertices[on, 2] == dual.grid // 2)
