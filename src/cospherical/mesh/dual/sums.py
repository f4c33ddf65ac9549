"""The mesh's sums: its edges and their coefficients, the control volumes and the boundary areas, exactly.

Every group's pieces (:mod:`~cospherical.mesh.dual.shapes`) are put over common
denominators once; each member then adds its pieces, times its size's power, to the
global arrays by integer array indexing: integer sums, exact in any order.  Floats
appear only in the ``float`` outputs (:func:`~cospherical.mesh.dual.arrays.as_floats`).
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any, Iterator, Protocol, Sequence

import numpy as np
from numpy.typing import DTypeLike, NDArray

from ...core.configuration import Box
from ..assembly import Mesh
from .arrays import Dual, ExactArray, as_floats, boundary_areas
from .shapes import Group, cell_groups, element_groups, leaf_groups

__all__ = ["GridVertices", "PACKED_BITS", "mesh_dual"]

# Instances per block of work: its temporaries (1 MiB each) stay below numpy's huge-page size (4 MiB) and inside
# the allocator's heap, which reuses them; blocks of 2**21 (16 MiB temporaries) were mapped, faulted in and
# unmapped anew each time: on the README's level-8 tree 0.1-0.3 s of system time more in mesh_dual (0.58 s
# against 0.45 s, median of 4-5 runs each)
_CHUNK = 1 << 17
_VALUES = 1 << 21  # entries of the table of each piece's numerator at each size, at most (see _edge_sums)
PACKED_BITS = 63  # an edge instance's key and payload share one int64 while they fit in these bits


class GridVertices(Protocol):
    """What :func:`mesh_dual` reads of a mesh when it is given the elements: its box, grid and integer vertices."""

    @property
    def box(self) -> Box: ...

    @property
    def grid(self) -> int: ...

    @property
    def vertices(self) -> NDArray[Any]: ...


def _chunks(count: int, width: int) -> Iterator[slice]:
    """Slices of ``range(count)`` of about ``_CHUNK`` / ``width`` rows each."""
    step = max(1, _CHUNK // max(width, 1))
    for start in range(0, count, step):
        yield slice(start, min(start + step, count))


def _over(numerators: list[int], denominator: int, common: int) -> list[int]:
    """Numerators over ``denominator`` put over its multiple ``common``."""
    factor = common // denominator
    return numerators if factor == 1 else [n * factor for n in numerators]


def _largest(numerators: list[int], denominator: int, common: int) -> int:
    """The largest numerator, in absolute value, over ``common`` (a multiple of ``denominator``)."""
    return max(map(abs, numerators), default=0) * (common // denominator)


def mesh_dual(mesh: Mesh | GridVertices, elements: tuple[NDArray[np.integer], NDArray[np.integer]] | None = None
              ) -> Dual:
    """The exact dual of a mesh.

    By default the elements are the elements of the mesh's leaf tessellations, and their pieces
    are computed once per configuration, and the cells that replace leaves (global
    Delaunay mode) once per shape.  ``elements`` (``(connectivity, sizes)`` as
    :meth:`Mesh.connectivity` gives them, global vertex ids) takes any element list
    on the mesh's vertices instead, for example cells that span leaves: each element
    is then measured from its vertices (faces: the hull of its nodes; centre: the
    sphere through them), once per distinct shape up to translation and scaling by
    powers of two.  Without ``elements`` the mesh must be a
    :class:`~cospherical.mesh.assembly.Mesh`.
    """
    box = mesh.box
    grid = int(mesh.grid)
    squared = (Fraction(box.squared[0]), Fraction(box.squared[1]), Fraction(box.squared[2]))
    factor_squared = squared[0] * squared[1] * squared[2]
    verts = np.asarray(mesh.vertices, dtype=np.int64)
    n_vertices = len(verts)
    # per group: its pieces, the array and rows that give its members' global vertex ids, their sizes
    if elements is None:
        if not isinstance(mesh, Mesh):
            raise TypeError("mesh_dual: give the elements of a mesh that is not an assembled Mesh")
        groups, centers = leaf_groups(mesh, squared)
        groups += cell_groups(mesh, squared, centers)
        elements = mesh.connectivity()
    else:
        groups, centers = element_groups(box, grid, verts, squared, *elements)
    cden = math.lcm(1, *(group.pieces.edge_denominator for group in groups))
    vden = math.lcm(1, *(group.pieces.volume_denominator for group in groups))
    bden = math.lcm(1, *(group.pieces.boundary_denominator for group in groups))
    max_size = max((int(group.sizes.max()) for group in groups if len(group.sizes)), default=1)
    # int64 sums while every product and sum is bounded below 2**62: the largest numerator (not just the
    # denominator: on tiny or huge domains the pieces over a*b*c are far from 1) times the size scaling,
    # times a bound on the pieces met by one edge or vertex
    largest_coefficient = max((_largest(p.edge_numerators, p.edge_denominator, cden) for p, *_ in groups), default=0)
    largest_volume = max((_largest(p.volume_numerators, p.volume_denominator, vden) for p, *_ in groups), default=0)
    largest_boundary = max((_largest([n for _, n in p.boundary], p.boundary_denominator, bden) for p, *_ in groups),
                           default=0)
    wide = largest_volume * max_size ** 3 * 4096 >= 2**62 or largest_coefficient * max_size * 4096 >= 2**62 or \
        largest_boundary * max_size ** 2 * 4096 >= 2**62
    dtype: DTypeLike = object if wide else np.int64
    edges, coefficient_exact = _edge_sums(groups, n_vertices, cden, dtype)
    boundary = np.any((verts == 0) | (verts == grid), axis=1)
    volume_exact: ExactArray = np.zeros(n_vertices, dtype=dtype)
    boundary_exact: ExactArray = np.zeros((n_vertices, 3), dtype=dtype)  # per axis: the area in the sides normal to it
    for shape, source, rows, sizes in groups:
        q = np.array(_over(shape.volume_numerators, shape.volume_denominator, vden), dtype=dtype)
        touching_parts = []  # the members with a vertex on the domain's boundary: only they have boundary areas
        for part in _chunks(len(rows), len(shape.volume_nodes)):
            ids = source[rows[part]][:, shape.volume_nodes]  # whole rows, then columns: twice a 2-D index's speed
            # integer sums, unbuffered: exact in any order (flat indices: numpy's fast path for ufunc.at, five
            # times a 2-D index's speed)
            np.add.at(volume_exact, ids.reshape(-1), (sizes[part, None].astype(dtype) ** 3 * q).reshape(-1))
            if shape.boundary:
                touching_parts.append(part.start + np.flatnonzero(boundary[ids].any(axis=1)))
        if not touching_parts:
            continue
        touching = np.concatenate(touching_parts)
        # every boundary share of every touching member at once: (member, share) tables of vertex ids and axes
        axes = np.array([axis for (axis, _, _), _ in shape.boundary], dtype=np.int64)
        nodes = np.array([node for (_, _, node), _ in shape.boundary], dtype=np.int64)
        shares = np.array(_over([n for _, n in shape.boundary], shape.boundary_denominator, bden), dtype=dtype)
        for part in _chunks(len(touching), len(nodes)):
            members = touching[part]
            ids = source[rows[members]][:, nodes].astype(np.int64)
            coordinate = verts[ids, axes]
            # the face lies in the vertex's plane: on the boundary where that plane is a side of the domain
            on = (coordinate == 0) | (coordinate == grid)
            values = sizes[members, None].astype(dtype) ** 2 * shares
            np.add.at(boundary_exact.reshape(-1), ids[on] * 3 + np.broadcast_to(axes, ids.shape)[on], values[on])
    lengths = np.array(box.to_float())
    real = verts * (lengths / grid)
    factor = math.sqrt(factor_squared)
    coefficient = as_floats(coefficient_exact, cden * grid, factor)
    length = _lengths(real, edges)
    control_volume = as_floats(volume_exact, vden * grid ** 3, factor)
    plane_squared = (squared[1] * squared[2], squared[2] * squared[0], squared[0] * squared[1])
    return Dual(box=box, grid=grid, grid_vertices=verts, vertices=real, edges=edges, length=length,
                area=coefficient * length, coefficient=coefficient, control_volume=control_volume, boundary=boundary,
                boundary_area=boundary_areas(boundary_exact, bden * grid ** 2, plane_squared),
                coefficient_exact=coefficient_exact, coefficient_denominator=cden * grid, volume_exact=volume_exact,
                volume_denominator=vden * grid ** 3, volume_factor=factor, volume_factor_squared=factor_squared,
                boundary_area_exact=boundary_exact, boundary_area_denominator=bden * grid ** 2,
                boundary_factors_squared=plane_squared, element_circumcenter=centers,
                element_nodes=elements[0], element_sizes=elements[1])


def _lengths(real: NDArray[np.float64], edges: NDArray[np.int64]) -> NDArray[np.float64]:
    """Each edge's length, one coordinate at a time: ``sqrt((dx*dx + dy*dy) + dz*dz)``, the order and so the
    bits of numpy's sum over a row of three (a loop over the edges' 3-vectors took four times as long).  In
    blocks of ``_CHUNK`` edges, into two buffers of the block's size: full-length differences were six arrays
    of every edge's size a coordinate, each mapped and zeroed anew by the system."""
    columns = [np.ascontiguousarray(real[:, axis]) for axis in range(3)]
    total: NDArray[np.float64] = np.empty(len(edges))
    ends, step = np.empty(min(_CHUNK, len(edges))), np.empty(min(_CHUNK, len(edges)))
    for part in _chunks(len(edges), 1):
        i, j = edges[part, 0], edges[part, 1]
        size = len(i)
        out, a, b = total[part], ends[:size], step[:size]
        for axis, column in enumerate(columns):
            np.take(column, j, out=b)
            np.take(column, i, out=a)
            np.subtract(b, a, out=b)
            if axis == 0:
                np.multiply(b, b, out=out)
            else:
                b *= b
                out += b
        np.sqrt(out, out=out)
    return total


def _edge_sums(groups: Sequence[Group], n_vertices: int, cden: int, dtype: DTypeLike
               ) -> tuple[NDArray[np.int64], ExactArray]:
    """The mesh's edges (m x 2, ``i < j``, sorted) and their summed coefficient numerators.

    Every edge instance (one edge of one group member) becomes an int64 key
    ``i * 2**v + j`` and a payload: its piece's index into the groups' numerators and
    its member's size as a power of two (coefficients scale with the size).  While key
    and payload fit one int64 together they are sorted as one array (a plain sort,
    several times faster than an argsort, which needs no second array to follow it);
    else the keys are argsorted and the payloads follow.  Both sorts are numpy's stable
    one (a merge sort that takes sorted runs as they come): the instances come group by
    group, member by member, and members near in the tree have near vertex ids, so the
    keys arrive in long runs; on the README's level-8 tree this halves the sort's time
    against the default quicksort.  Equal keys are then runs, summed in integers: exact
    in any order.
    """
    table: list[int] = []
    offsets: list[int] = []
    total, max_shift = 0, 0
    for shape, _, rows, sizes in groups:
        offsets.append(len(table))
        table.extend(_over(shape.edge_numerators, shape.edge_denominator, cden))
        total += len(rows) * len(shape.edges)
        if len(sizes):
            max_shift = max(max_shift, int(sizes.max()).bit_length() - 1)
    shift_bits = max_shift.bit_length()
    payload_bits = (max(len(table) - 1, 0)).bit_length() + shift_bits
    vertex_bits = max(n_vertices - 1, 1).bit_length()
    packed = 2 * vertex_bits + payload_bits <= PACKED_BITS
    keys = np.empty(total, dtype=np.int64)
    payloads = keys if packed else np.empty(total, dtype=np.int64)
    at = 0
    for (shape, source, rows, sizes), offset in zip(groups, offsets):
        count = len(shape.edges)
        if not count:
            continue
        shifts = np.log2(sizes).astype(np.int64)  # sizes are powers of two: exact
        pieces = (offset + np.arange(count, dtype=np.int64)) << shift_bits
        for part in _chunks(len(rows), count):
            members = source[rows[part]]  # whole rows, then columns: twice a 2-D index's speed
            a = members[:, shape.edges[:, 0]]
            b = members[:, shape.edges[:, 1]]
            end = at + a.size
            key = keys[at:end].reshape(a.shape)  # written in place: (min << vertex_bits | max), then the payload
            np.left_shift(np.minimum(a, b), vertex_bits, out=key, dtype=np.int64)
            key |= np.maximum(a, b)
            payload = pieces | shifts[part, None]
            if packed:
                key <<= payload_bits
                key |= payload
            else:
                payloads[at:end] = payload.reshape(-1)
            at = end
    key_shift = payload_bits if packed else 0
    if packed:
        keys.sort(kind="stable")
    else:
        order = np.argsort(keys, kind="stable")
        keys, payloads = keys[order], payloads[order]
        del order
    starts = np.ones(total, dtype=bool)
    for part in _chunks(total - 1, 1):
        starts[part.start + 1:part.stop + 1] = (keys[part.start + 1:part.stop + 1] >> key_shift) != (
            keys[part] >> key_shift)
    first = np.flatnonzero(starts)
    del starts
    unique = keys[first]
    unique >>= key_shift
    edges = np.empty((len(first), 2), dtype=np.int64)
    np.right_shift(unique, vertex_bits, out=edges[:, 0])
    np.bitwise_and(unique, (1 << vertex_bits) - 1, out=edges[:, 1])
    del unique
    numerators = np.array(table, dtype=dtype)
    # each payload's value, its piece's numerator times its member's size, from one table indexed by the payload
    # while that table is small (no member is larger than 2**max_shift: the columns past it are never read)
    values = None
    if len(table) << shift_bits <= _VALUES:
        powers = np.zeros(1 << shift_bits, dtype=dtype)
        powers[:max_shift + 1] = [1 << k for k in range(max_shift + 1)]
        values = (numerators[:, None] * powers[None, :]).reshape(-1)
    sums: ExactArray = np.empty(len(first), dtype=dtype)
    # blocks of whole runs, so that each run is summed within one block
    # (marks in increasing order, each once: np.unique would import numpy.ma, 15 ms of a run, to ask if they are masked)
    marks = np.r_[np.searchsorted(first, np.arange(0, total, _CHUNK)), len(first)]
    bounds = marks[np.r_[True, marks[1:] != marks[:-1]]]
    for lo, hi in zip(bounds[:-1], bounds[1:]):
        start, stop = first[lo], first[hi] if hi < len(first) else total
        payload = payloads[start:stop] & ((1 << payload_bits) - 1)
        parts = values[payload] if values is not None else \
            numerators[payload >> shift_bits] << (payload & ((1 << shift_bits) - 1)).astype(dtype)
        sums[lo:hi] = np.add.reduceat(parts, first[lo:hi] - start)
    return edges, sums
