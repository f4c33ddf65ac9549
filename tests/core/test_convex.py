"""A convex polyhedron from corners, edges and faces, checked exactly: every refusal, and the faces turned
outward (checked against Qhull's hull of the same corners)."""

from fractions import Fraction

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from cospherical import InputError, Shape
from cospherical.core.convex import convex_polyhedron

SQUARE = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
PYRAMID_EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (0, 4), (1, 4), (2, 4), (3, 4)]
PYRAMID_FACES = [(0, 1, 2, 3), (0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)]


@pytest.mark.parametrize("vertices, edges, faces, message", [
    (SQUARE + [(0, 0, 0)], PYRAMID_EDGES, PYRAMID_FACES, "corners 0 and 4 are the same point"),
    (SQUARE + [(1, 1, 0)], PYRAMID_EDGES, PYRAMID_FACES, "same point"),
    (SQUARE + [(2, 2, 0)], PYRAMID_EDGES, PYRAMID_FACES, "coplanar"),
    (SQUARE + [("1/2", "1/2", "1/2")], PYRAMID_EDGES, [(0, 1, 3, 2), *PYRAMID_FACES[1:]], "not a convex polygon"),
    ([(0, 0, 0), (1, 0, 0), (1, 1, "1/2"), (0, 1, 0), ("1/2", "1/2", 1)], PYRAMID_EDGES, PYRAMID_FACES,
     "not on one plane"),
    (SQUARE + [("1/2", "1/2", 1), ("1/2", "1/2", "1/4")], PYRAMID_EDGES, PYRAMID_FACES, "corner 5 is on no face"),
    (SQUARE + [("1/2", "1/2", 1)], PYRAMID_EDGES[:-1], PYRAMID_FACES, "is not among the edges"),
    (SQUARE + [("1/2", "1/2", 1)], PYRAMID_EDGES + [(0, 2)], PYRAMID_FACES, "not a side of any face"),
    (SQUARE + [("1/2", "1/2", 1)], PYRAMID_EDGES, PYRAMID_FACES[:-1], "do not close the surface"),
    ([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), ("1/6", "1/6", "1/6")],  # a tetrahedron with a dent
     [(0, 1), (0, 2), (0, 3), (1, 2), (2, 3), (3, 1), (1, 4), (2, 4), (3, 4)],
     [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 4), (2, 3, 4), (3, 1, 4)], "not convex"),
    (SQUARE + [("1/2", "1/2", 1), ("1/2", 0, 0)], PYRAMID_EDGES, PYRAMID_FACES, "corner 5 lies in the plane"),
    (SQUARE + [(0.5, 0.5, 1)], PYRAMID_EDGES, PYRAMID_FACES, "not a float"),
])
def test_bad_vertices_are_refused(vertices, edges, faces, message):
    with pytest.raises(InputError, match=message):
        convex_polyhedron(vertices, edges, faces)
    with pytest.raises(InputError, match=message):  # a shape is built through it
        Shape.from_vertices(vertices, edges, faces)


@pytest.mark.oracle_qhull
def test_faces_turn_outward_and_planes_hold_the_corners():
    # The pyramid's faces given clockwise and counter-clockwise alike: every one comes back with its
    # outward normal, the direction Qhull's hull gives the facet in the same plane.
    faces = [tuple(reversed(f)) if i % 2 else f for i, f in enumerate(PYRAMID_FACES)]
    corners, edges, oriented, planes = convex_polyhedron(SQUARE + [("1/2", "1/2", 1)], PYRAMID_EDGES, faces)
    assert corners[4] == (Fraction(1, 2), Fraction(1, 2), 1) and len(edges) == 8
    assert [set(f) for f in oriented] == [set(f) for f in PYRAMID_FACES]
    hull = ConvexHull(np.array(corners, dtype=float))
    for cycle, (normal, offset) in zip(oriented, planes):
        assert all(sum(n * x for n, x in zip(normal, corners[i])) == offset for i in cycle)
        assert all(sum(n * x for n, x in zip(normal, c)) <= offset for c in corners)
        unit = np.array(normal, dtype=float) / np.linalg.norm(np.array(normal, dtype=float))
        assert any(np.allclose(unit, equation[:3]) for equation in hull.equations)  # Qhull's outward normal
