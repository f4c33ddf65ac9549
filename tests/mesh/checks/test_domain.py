"""Where the domain is: its boundary and its closed inside, for a box and for a device's union of boxes, exactly."""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from cospherical.mesh.checks import in_closed_domain, on_domain_boundary
from cospherical.mesh.device import Device, Region, device_layout


def test_a_point_is_in_the_closed_union_of_boxes_exactly():
    """Where a device's circumcentres may lie: an L's notch is outside, its walls and re-entrant edge inside
    (against the boxes, in Fractions)."""
    def box(*values):
        return tuple(Fraction(v) for v in values)

    layout = device_layout(Device("l", (Region("a", "Si", (box(0, 0, 0, 2, 1, 1), box(0, 1, 0, 1, 2, 1))),), (),
                                  (), 1))
    grid = 8  # grid units: the L is the boxes (0, 0, 0)-(8, 4, 8) and (0, 4, 0)-(4, 8, 8)
    boxes = [(0, 0, 0, 8, 4, 8), (0, 4, 0, 4, 8, 8)]
    third = Fraction(1, 3)
    points = [(5, 5, 1), (4, 5, 1), (5, 4, 1), (4, 4, 8), (4 + third, 4 + third, 1), (8, 4, 0), (8 + third, 1, 1),
              (1, 8, 8), (4 - third, 8, third), (4 + third, 8, 1), (2, 2, -third)]
    want = [any(all(b[a] <= p[a] <= b[a + 3] for a in range(3)) for b in boxes) for p in points]
    num = np.array([[int(Fraction(x) * 3) for x in p] for p in points], dtype=np.int64)
    assert in_closed_domain(num, np.full((len(num), 1), 3, dtype=np.int64), grid, layout).tolist() == want
    assert sum(want) not in (0, len(want))


def test_a_face_is_in_the_boxs_boundary_when_all_its_corners_share_a_side():
    grid = 4
    faces = np.array([[[0, 0, 0], [0, 4, 0], [0, 4, 4]],  # in the side x = 0
                      [[4, 1, 1], [4, 2, 1], [4, 2, 3]],  # in x = 4
                      [[0, 0, 0], [4, 0, 0], [4, 0, 4]],  # in y = 0
                      [[1, 1, 4], [2, 1, 4], [2, 3, 4]],  # in z = 4
                      [[0, 0, 0], [4, 4, 0], [4, 4, 4]],  # a diagonal plane through an edge of the box
                      [[0, 0, 1], [0, 1, 1], [1, 1, 0]],  # one corner in a side, not the face
                      [[2, 2, 2], [3, 2, 2], [3, 3, 2]]])  # inside
    assert on_domain_boundary(faces, grid).tolist() == [True, True, True, True, False, False, False]
