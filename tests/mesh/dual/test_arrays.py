"""The dual's arrays and what they answer (cospherical.mesh.dual.arrays): negative coefficients, matrices."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from cospherical.core.configuration import Box
from cospherical.mesh.assembly import assemble
from cospherical.mesh.dual import mesh_dual
from cospherical.mesh.octree import build_octree, parse_shape

from ..test_dual import CACHES


def test_a_non_delaunay_mesh_shows_its_negative_coefficients():
    """1 x 2 x 4 octrees are not globally Delaunay: the coefficients say so, nothing is clipped."""
    box = Box.parse(["1", "2", "4"])
    mesh = assemble(build_octree(box, 3, [parse_shape("point:1/5,3/10,2/5")]),
                    cache=CACHES.setdefault(box.texts, {}))
    dual = mesh_dual(mesh)
    negative = dual.negative_coefficients()
    assert negative.interior > 0
    assert negative.interior + negative.boundary == int((dual.coefficient < 0).sum())
    assert dual.volume_sum() == 1




def test_the_matrices_are_the_coefficients_and_the_control_volumes():
    """laplacian(): -coefficient off the diagonal, zero row sums, symmetric; mass(): the control volumes."""
    box = Box.parse(["1", "2", "4"])
    dual = mesh_dual(assemble(build_octree(box, 2, [parse_shape("point:1/3,1/5,1/7")]),
                              cache=CACHES.setdefault(box.texts, {})))
    laplacian = dual.laplacian()
    assert laplacian.nnz == len(dual.vertices) + 2 * len(dual.edges)  # one stored entry per position
    k, m = laplacian.toarray(), dual.mass().toarray()
    i, j = dual.edges.T
    assert np.array_equal(k[i, j], -dual.coefficient) and np.array_equal(k, k.T)
    assert np.abs(k.sum(axis=1)).max() <= 1e-12 * np.abs(dual.coefficient).max()
    assert np.array_equal(np.diag(m), dual.control_volume) and np.count_nonzero(m - np.diag(np.diag(m))) == 0


def test_exact_numerators_become_the_same_floats_as_int64_or_python_integers():
    """as_floats divides Python integers (numbers past float's range) exactly first: the int64 path's floats
    where both apply, and finite floats where int64 and float both overflow."""
    from cospherical.mesh.dual import as_floats

    small = np.array([-7, 0, 3, 2**40 + 1], dtype=np.int64)
    assert np.array_equal(as_floats(small.astype(object), 12, 1.0), small / 12.0)
    huge = np.array([10**400, -(10**400) * 3], dtype=object)
    assert as_floats(huge, 10**400, 0.5).tolist() == [0.5, -1.5]


@settings(max_examples=50, deadline=None)
@given(st.lists(st.integers(-2**62, 2**62), max_size=40), st.booleans())
def test_exact_sums_are_pythons_sums(values, wide):
    """The sums of exact numerators (volume sums, areas per axis, per region, contact and interface) equal Python's
    sum of the integers, in int64 where that cannot overflow and past it (here: values near 2**62, object arrays)."""
    from cospherical.mesh.dual.arrays import _exact_sum

    array = np.array(values, dtype=object if wide else np.int64)
    assert _exact_sum(array) == sum(values)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([(1, 1, 1), (8, 2, 4), (2, 3, 6)]), st.integers(1, 2**40))
def test_boundary_areas_are_numpys_row_sums_bit_for_bit(seed, squares, denominator):
    """The boundary areas, summed one axis at a time, are bit for bit numpy's sum over each row of the three
    products, divided by the denominator (the members boundary_area keep their bits)."""
    from fractions import Fraction

    from cospherical.mesh.dual import boundary_areas

    exact = np.random.default_rng(seed).integers(-2**50, 2**50, size=(60, 3))
    factors = [Fraction(f) for f in squares]
    expected = (exact.astype(np.float64) * np.sqrt(np.array(squares, dtype=np.float64))).sum(axis=1) / denominator
    assert np.array_equal(boundary_areas(exact, denominator, factors).view(np.int64), expected.view(np.int64))
