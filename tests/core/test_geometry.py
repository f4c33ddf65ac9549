"""The exact kernel (core/geometry.py): its bulk backends agree, its constructions are what they claim."""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from cospherical.core.geometry import Frame


def test_the_kernels_bulk_backends_agree():
    # int64 (under each function's bound) and Python integers: the same numbers, on random tetrahedra
    # whose coordinates reach the bound's scale, flat ones and a shared sphere among them
    from cospherical.core import geometry

    rng = np.random.default_rng(5)
    tets = rng.integers(0, 1 << 12, size=(300, 4, 3))
    tets[:20, 3] = tets[:20, 0] + tets[:20, 1] - tets[:20, 2]  # flat: a parallelogram
    cube = np.array([[0, 0, 0], [8, 0, 0], [0, 8, 0], [0, 0, 8], [8, 8, 8]])
    tets[20:40] = cube[[0, 1, 2, 3]] + rng.integers(0, 1 << 10, size=(20, 1, 3))
    points = rng.integers(0, 1 << 12, size=(300, 3))
    points[20:40] = tets[20:40, 0] + 8  # on the cube's sphere
    weights = (1, 2, 3)
    six = geometry.six_volumes(tets)
    assert six.dtype == np.int64 and (six[:20] == 0).all() and (six[20:] != 0).all()
    assert six.tolist() == geometry.six_volumes(tets, python_integers=True).tolist()
    solid = tets[20:]
    sides = geometry.sphere_sides(solid, points[20:], weights)
    assert sides.tolist() == geometry.sphere_sides(solid, points[20:], weights, python_integers=True).tolist()
    assert (sides[:20] == 0).all() and {-1, 1} <= set(sides[20:].tolist())
    fast, exact = geometry.circumcenters(solid, weights), geometry.circumcenters(solid, weights, python_integers=True)
    assert fast[0].dtype == np.int64 and exact[0].dtype == object
    assert [a.tolist() for a in fast] == [a.tolist() for a in exact]
    # each centre is equidistant (weighted) from its four vertices
    for tet, num, den in zip(solid[:5].tolist(), *(a[:5].tolist() for a in exact)):
        center = [Fraction(n, d) for n, d in zip(num, den)]
        assert len({sum(w * (x - c) ** 2 for w, x, c in zip(weights, p, center)) for p in tet}) == 1


def test_right_angles_are_decided_in_the_real_metric():
    # squared lengths (1, 2, 3): the frame's unit square is a rectangle, a parallelogram is not, and
    # edges (1, 1, 0) and (-2, 1, 0), not perpendicular in the frame, are in the box (1 * -2 + 2 * 1 = 0)
    points = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (2, 1, 0), (-1, 2, 0), (-2, 1, 0)]
    frame = Frame.build(dict(enumerate(points)), (Fraction(1), Fraction(2), Fraction(3)))
    assert frame.right_angled((0, 1, 2, 3))
    assert not frame.right_angled((0, 1, 4, 2))
    assert frame.right_angled((0, 2, 5, 6))
    assert frame.real_dot((1, 1, 0), (-2, 1, 0)) == 0 and sum(a * b for a, b in zip((1, 1, 0), (-2, 1, 0))) != 0
