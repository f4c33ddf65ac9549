"""The Morton (Z-order) curve: the one encoder of every ordering by it.

A point of an integer grid gets the number whose bits are its coordinates' bits
interleaved, x, y, z from the most significant down; sorted by it, the points
walk the grid along the Z-order curve, so points near on the curve are near in
space.  The exact Delaunay engine inserts its points in this order, the mesh's
Delaunay check queries its spheres in it, and a partitioned tree is cut into
runs of it.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["MAX_BITS", "morton_codes"]

MAX_BITS = 21  # per coordinate: three times 21 bits fit an int64

# Spreading 21 bits two zeros apart in five shift-and-mask steps (each mask keeps the bits that
# the next step moves as one block), in uint64: bits that leave the word are masked off anyway.
_SPREAD = ((32, 0x1F00000000FFFF), (16, 0x1F0000FF0000FF), (8, 0x100F00F00F00F00F), (4, 0x10C30C30C30C30C3),
           (2, 0x1249249249249249))


def morton_codes(cells: ArrayLike) -> NDArray[Any]:
    """Per row of ``cells`` (n, 3), nonnegative integers, its place on the Z-order curve.

    int64 for coordinates below ``2**MAX_BITS``; for larger ones (the exact engine
    takes any integers) Python integers, in an object array: the same numbers.

    >>> morton_codes([[0, 0, 1], [0, 1, 0], [1, 0, 0], [1, 1, 1], [2, 0, 0]]).tolist()
    [1, 2, 4, 7, 32]
    """
    cells = np.asarray(cells)
    if not len(cells):
        return np.zeros(0, dtype=np.int64)
    if cells.dtype == object or int(cells.max()) >> MAX_BITS:
        cells = cells.astype(object)
        code = np.zeros(len(cells), dtype=object)
        for bit in range(int(cells.max()).bit_length()):
            for axis in range(3):
                code = code | (((cells[:, axis] >> bit) & 1) << (3 * bit + 2 - axis))
        return code
    code = np.zeros(len(cells), dtype=np.uint64)
    for axis in range(3):
        spread = cells[:, axis].astype(np.uint64)
        for shift, mask in _SPREAD:
            spread = (spread | (spread << np.uint64(shift))) & np.uint64(mask)
        code |= spread << np.uint64(2 - axis)
    return code.astype(np.int64)
