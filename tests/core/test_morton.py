"""The one Morton encoder: bits interleaved x, y, z from the most significant down, at every scale."""

from __future__ import annotations

import numpy as np

from cospherical.core.morton import MAX_BITS, morton_codes


def interleaved(point: list[int]) -> int:
    code = 0
    for bit in range(max(point).bit_length() - 1, -1, -1):
        for x in point:
            code = (code << 1) | (x >> bit & 1)
    return code


def test_codes_interleave_the_bits_in_int64_and_beyond():
    rng = np.random.default_rng(3)
    for bits in (1, 10, MAX_BITS, MAX_BITS + 1, 70):
        cells = [[int(x) for x in rng.integers(0, 1 << min(bits, 62), size=3)] for _ in range(200)]
        cells += [[(1 << bits) - 1] * 3, [0, 0, 0], [(1 << bits) - 1, 0, 0]]
        codes = morton_codes(cells)
        assert codes.dtype == (np.int64 if bits <= MAX_BITS else object)
        assert codes.tolist() == [interleaved(p) for p in cells], bits
    assert morton_codes(np.zeros((0, 3), dtype=np.int64)).tolist() == []
