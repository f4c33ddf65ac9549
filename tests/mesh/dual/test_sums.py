"""mesh_dual's sums (cospherical.mesh.dual.sums): the bulk scatter equals element-by-element sums, in any int width."""

from __future__ import annotations

from fractions import Fraction

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cospherical.core.configuration import Box
from cospherical.mesh.assembly import assemble
from cospherical.mesh.dual import mesh_dual
from cospherical.mesh.octree import build_octree, parse_shape

from ..test_dual import octrees


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
@given(octrees(), st.booleans(), st.booleans())
def test_bulk_sums_equal_leaf_by_leaf_sums_exactly(mesh, packed, small_blocks):
    """The sorted bulk sums (key and payload packed in one int64, or argsorted apart; in blocks of 2**17
    instances with each payload's value from one table, or in blocks of 16 with the numerators shifted by
    the sizes) are the leaf-by-leaf sums."""
    from cospherical.mesh.dual import sums as module

    saved, chunk, values = module.PACKED_BITS, module._CHUNK, module._VALUES
    module.PACKED_BITS = saved if packed else 0  # 0: nothing fits, the argsort path
    module._CHUNK, module._VALUES = (16, 16) if small_blocks else (chunk, values)  # 16: no payload table fits
    try:
        dual = mesh_dual(mesh)
    finally:
        module.PACKED_BITS, module._CHUNK, module._VALUES = saved, chunk, values
    coefficients, volumes = reference_sums(mesh)
    assert list(map(tuple, dual.edges.tolist())) == sorted(coefficients)
    grid = Fraction(dual.grid)
    assert [Fraction(int(c), dual.coefficient_denominator) * grid for c in dual.coefficient_exact] == [
        coefficients[key] for key in sorted(coefficients)]
    assert [Fraction(int(v), dual.volume_denominator) * grid ** 3 for v in dual.volume_exact] == [
        volumes[n] for n in range(len(dual.vertices))]


@pytest.mark.parametrize("domain", [["1e-12", "1e-12", "1e-12"], ["1e-12", "1", "1"], ["3e9", "1", "1"]])
def test_the_dual_of_tiny_and_huge_domains_is_exact(domain, tmp_path):
    from cospherical.formats.dual import read_dual, write_dual

    box = Box.parse(domain)
    dual = mesh_dual(assemble(build_octree(box, 2, [parse_shape("point:0,0,0")])))
    assert dual.volume_sum() == 1  # the control volumes fill the domain, as a fraction of its volume
    assert dual.boundary_area_sums() == (2, 2, 2)  # and the boundary areas its surface
    assert dual.negative_coefficients().interior == 0
    write_dual(dual, tmp_path / "dual.npz")  # integers too wide for int64 go as decimal text, and come back
    again = read_dual(tmp_path / "dual.npz")
    for name in ("coefficient_exact", "volume_exact", "boundary_area_exact"):
        assert getattr(again, name).tolist() == getattr(dual, name).tolist()


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([1.0, 1e-12, 3e9, 1 / 3]), st.sampled_from([7, 1 << 17]))
def test_edge_lengths_are_numpys_row_sums_bit_for_bit(seed, scale, block):
    """The lengths, summed one coordinate at a time (in blocks of edges), are bit for bit those of numpy's sum
    over each edge's row of three squares (the dual.npz member ``length`` keeps its bits)."""
    from unittest import mock

    import numpy as np

    from cospherical.mesh.dual import sums

    rng = np.random.default_rng(seed)
    real = rng.random((50, 3)) * scale * rng.choice([1.0, 2.0 ** -30, 2.0 ** 30], size=(50, 3))
    edges = np.sort(rng.integers(0, 50, size=(200, 2)), axis=1)
    expected = np.sqrt(((real[edges[:, 1]] - real[edges[:, 0]]) ** 2).sum(axis=1))
    with mock.patch.object(sums, "_CHUNK", block):
        lengths = sums._lengths(real, edges)
    assert np.array_equal(lengths.view(np.int64), expected.view(np.int64))
