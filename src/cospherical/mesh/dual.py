"""The finite-volume dual of a mesh: control volumes and coupling coefficients, exactly.

The box method (vertex-centred finite volumes) gives every vertex the part of the
domain nearer to it than to any other vertex (its Voronoi cell, clipped to the
domain) and couples two vertices joined by a mesh edge with the area of their
common Voronoi face over the edge's length.  In a mesh of co-spherical elements
both are sums of element-wise pieces: inside an element with circumcenter ``c`` the
dual face of its edge ``(u, v)`` is the polygon ``m, f1, c, f2`` (``m`` the edge's
midpoint, ``f1, f2`` the centres of the circles of the two faces at the edge), and
the vertex ``u`` gets the pyramids over those pieces, of volume ``|e| * area / 6``::

            v
           /|\\          one face at edge (u, v), seen from outside:
          / | \\         f is the face's circle centre; the triangle
         /  m--f        (m, f, c) is the face's share of the dual
        /   |   \\       face of (u, v); c lies behind the page
       u----+----

A piece is signed (negative where ``c`` or ``f`` lies beyond the face or the edge), so
the sums are right for every element list and never hide a non-Delaunay mesh: its
coefficients come out negative, and are counted.  Only polygon edges of element
faces are edges; a diagonal inside a polygon face has a dual face of zero area.

Exact: with points ``(s*a, t*b, u*c)`` in unit coordinates and the squared lengths
``w = (a^2, b^2, c^2)`` (rational also for sqrt boxes), a face centre is
``c - (d.N / sum N_k^2/w_k) * N/w`` and a triangle's piece of ``area / length`` is
``a*b*c * (x_u - x_v).((f - m) x (c - m)) / (2 |e|^2)``: a rational times ``a*b*c``.
Volumes are rationals times ``a*b*c`` too, boundary areas rationals times the
product of the two lengths of their plane (kept per axis: on a sqrt box the three
products are different square roots).  Signs (negative coefficients) are
therefore decided on the rationals.  The pieces of a leaf's configuration scale
with the leaf's size (coefficients as ``h``, areas as ``h^2``, volumes as ``h^3``), so
they are computed once per configuration, and the mesh's sums are integer sums,
assembled by array indexing; floats appear only in the ``float`` outputs.

Examples
--------
>>> from cospherical.core.configuration import Box
>>> from cospherical.mesh.octree import build_octree, parse_shape
>>> from cospherical.mesh.assembly import assemble
>>> dual = mesh_dual(assemble(build_octree(Box.parse([1, 1, 1]), 1, [parse_shape("point:0.5,0.5,0.5")])))
>>> len(dual.edges), dual.volume_sum(), float(dual.control_volume.max())
(54, Fraction(1, 1), 0.125)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from ..core.configuration import Box
from ..core.geometry import Frame, determinant, plane_normal, plane_projection, six_volumes, sub
from ..core.polyhedron import measure
from ..errors import InputError
from .octree import distinct

__all__ = ["Dual", "ElementPieces", "RegionParts", "TETRAHEDRAL_LIMIT", "boundary_areas", "dual_summary",
           "element_pieces", "external_tetrahedra", "mesh_dual", "tetrahedral_counts"]

Point = tuple[Fraction, Fraction, Fraction]


@dataclass(frozen=True)
class ElementPieces:
    """One element's exact pieces, in a frame where the box has squared lengths ``w``.

    ``edges``: ``{(u, v): q}`` with ``u < v`` node ids and ``q`` the element's share of
    the edge's ``area / length`` over ``a*b*c``; ``volumes``: ``{u: q}`` each vertex's
    share of the element's volume over ``a*b*c``; ``boundary``: for each face that
    lies in a coordinate plane ``(axis, value)``, ``{u: q}`` each vertex's share of the
    face's area over the product of the plane's two lengths.
    """

    edges: dict[tuple[int, int], Fraction]
    volumes: dict[int, Fraction]
    boundary: dict[tuple[int, Fraction], dict[int, Fraction]]


def element_pieces(points: Mapping[int, Point], faces: Sequence[Sequence[int]], center: Point,
                   squared: Sequence[Fraction]) -> ElementPieces:
    """The exact dual pieces of one co-spherical element.

    ``points``: node id -> unit coordinates; ``faces``: the element's face cycles,
    counter-clockwise seen from outside; ``center``: its circumcenter in unit
    coordinates; ``squared``: the box's squared lengths.

    Examples
    --------
    >>> cube = {n: tuple(Fraction(x) for x in p) for n, p in enumerate(
    ...     [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)])}
    >>> faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    >>> half = Fraction(1, 2)
    >>> pieces = element_pieces(cube, faces, (half, half, half), (1, 1, 1))
    >>> pieces.edges[0, 1], pieces.volumes[0], len(pieces.edges), pieces.boundary[2, 0][0]
    (Fraction(1, 4), Fraction(1, 8), 12, Fraction(1, 4))
    """
    # Integers throughout, one fraction per face and edge: coordinates times D (midpoints stay
    # integers), squared lengths as integer weights W = lam * w, a face centre times D * S
    w = tuple(Fraction(x) for x in squared)
    lam = math.lcm(*(x.denominator for x in w))
    weight = tuple(int(x * lam) for x in w)
    inverse = tuple(math.lcm(*weight) // x for x in weight)
    scale = 2 * math.lcm(*(Fraction(x).denominator for p in (*points.values(), center) for x in p))
    ip = {n: tuple(int(Fraction(x) * scale) for x in p) for n, p in points.items()}
    ic = tuple(int(Fraction(x) * scale) for x in center)
    edges: dict[tuple[int, int], Fraction] = {}
    volumes: dict[int, Fraction] = {n: Fraction(0) for n in points}
    boundary: dict[tuple[int, Fraction], dict[int, Fraction]] = {}
    for cycle in faces:
        p0, p1, p2 = (ip[n] for n in cycle[:3])
        normal = plane_normal(p0, p1, p2)  # no three points of a circle are collinear
        face_center, s = plane_projection(ic, p0, normal, inverse)  # the face's circle centre, times D * S
        cs = tuple(x * s for x in ic)
        plane = [k for k in range(3) if normal[k] != 0]
        shares = None
        if len(plane) == 1:  # in a coordinate plane: it may be on the domain's boundary
            k = plane[0]
            shares = boundary.setdefault((k, Fraction(p0[k], scale)), {})
            outward = 1 if normal[k] > 0 else -1
            face_area: dict[int, int] = {}
        face_volume: dict[int, int] = {}
        for u, v in zip(cycle, (*cycle[1:], cycle[0])):
            xu, xv = ip[u], ip[v]
            mid = tuple((xu[k] + xv[k]) // 2 * s for k in range(3))
            along = sub(xu, xv)
            piece = determinant(along, sub(face_center, mid), sub(cs, mid))  # times D^3 S^2
            length2 = sum(weight[k] * along[k] * along[k] for k in range(3))  # times lam D^2
            key = (u, v) if u < v else (v, u)
            edges[key] = edges.get(key, Fraction(0)) + Fraction(piece * lam, 2 * scale * s * s * length2)
            face_volume[u] = face_volume.get(u, 0) + piece
            face_volume[v] = face_volume.get(v, 0) + piece
            if shares is not None:
                # triangles (x_u, m, f) and (m, x_v, f): equal areas, half a base each (times D^2 S^2)
                xs = tuple(x * s for x in xu)
                area = outward * plane_normal(xs, mid, face_center)[k]
                face_area[u] = face_area.get(u, 0) + area
                face_area[v] = face_area.get(v, 0) + area
        for node, total in face_volume.items():
            volumes[node] += Fraction(total, 12 * scale ** 3 * s * s)
        if shares is not None:
            for node, total in face_area.items():
                shares[node] = shares.get(node, Fraction(0)) + Fraction(total, 2 * scale * scale * s * s)
    return ElementPieces(edges, volumes, boundary)


@dataclass
class Dual:
    """The dual of a mesh, as arrays (floats) with their exact integer forms.

    Vertices: ``grid_vertices`` (n x 3, integers of the grid of ``grid`` intervals per
    domain side) and ``vertices`` (their real coordinates); ``boundary`` (on the
    domain's boundary), ``control_volume``, ``boundary_area``.  Edges: ``edges``
    (m x 2, ``i < j``, sorted), ``length``, ``area`` (signed area of the dual face),
    ``coefficient`` (``area / length``).  Exact: ``coefficient == coefficient_exact *
    volume_factor / coefficient_denominator`` and ``control_volume == volume_exact *
    volume_factor / volume_denominator`` with integer numerators (int64, or Python
    integers in an object array when int64 could overflow) and ``volume_factor`` the
    box's ``a*b*c`` (``volume_factor_squared`` exact).  Boundary areas per axis ``k``
    (the part in the domain's two sides normal to ``k``): ``boundary_area ==
    sum over k of boundary_area_exact[:, k] * sqrt(boundary_factors_squared[k]) /
    boundary_area_denominator``, ``boundary_factors_squared`` the squared products of the
    two lengths of those sides, ``(b^2 c^2, a^2 c^2, a^2 b^2)``.  ``element_circumcenter``:
    the real circumcenter of every element, in the mesh's element order; ``element_nodes``
    and ``element_sizes``: the elements themselves (global vertex ids, padded with -1,
    as :meth:`~cospherical.mesh.assembly.Mesh.connectivity` gives them), from which the
    exact values can be computed again (``cospherical check`` does).
    """

    box: Box
    grid: int
    grid_vertices: np.ndarray
    vertices: np.ndarray
    edges: np.ndarray
    length: np.ndarray
    area: np.ndarray
    coefficient: np.ndarray
    control_volume: np.ndarray
    boundary: np.ndarray
    boundary_area: np.ndarray
    coefficient_exact: np.ndarray
    coefficient_denominator: int
    volume_exact: np.ndarray
    volume_denominator: int
    volume_factor: float
    volume_factor_squared: Fraction
    boundary_area_exact: np.ndarray
    boundary_area_denominator: int
    boundary_factors_squared: tuple[Fraction, Fraction, Fraction]
    element_circumcenter: np.ndarray = field(repr=False)
    element_nodes: np.ndarray = field(repr=False)
    element_sizes: np.ndarray = field(repr=False)
    regions: "RegionParts | None" = field(default=None, repr=False)

    def laplacian(self):
        """The box method's matrix: ``K[i, j] = -coefficient``, ``K[i, i]`` the row's sum (scipy.sparse CSR).

        Symmetric with zero row sums: ``K @ u`` is ``-div grad u`` integrated over the
        control volumes, so ``K u = M f`` with :meth:`mass` is the discrete Poisson
        problem.
        """
        from scipy.sparse import coo_matrix

        n = len(self.vertices)
        i, j = self.edges[:, 0], self.edges[:, 1]
        c = self.coefficient
        diagonal = np.bincount(i, weights=c, minlength=n) + np.bincount(j, weights=c, minlength=n)
        # one entry per position (no duplicates to sum), 32-bit indices while they fit: a third of the memory
        index = np.int32 if n < 2**31 else np.int64
        every = np.arange(n, dtype=index)
        rows = np.concatenate([i.astype(index), j.astype(index), every])
        cols = np.concatenate([j.astype(index), i.astype(index), every])
        return coo_matrix((np.concatenate([-c, -c, diagonal]), (rows, cols)), shape=(n, n)).tocsr()

    def mass(self):
        """The lumped mass matrix: the control volumes on the diagonal (scipy.sparse)."""
        from scipy.sparse import diags

        return diags(self.control_volume).tocsr()

    def volume_sum(self) -> Fraction:
        """The control volumes' sum as an exact fraction of the domain's volume."""
        return Fraction(int(np.sum(self.volume_exact.astype(object))), self.volume_denominator)

    def boundary_area_sums(self) -> tuple[Fraction, Fraction, Fraction]:
        """Per axis, the boundary areas' sum as an exact fraction of one side's area (2: both sides normal to it)."""
        return tuple(Fraction(int(np.sum(self.boundary_area_exact[:, k].astype(object))), self.boundary_area_denominator)
                     for k in range(3))

    def negative_coefficients(self) -> dict:
        """Edges whose coefficient is negative (decided on the exact integers), interior and boundary apart.

        A boundary edge lies in one of the domain's boundary planes.
        """
        negative = self.coefficient_exact < 0
        g = self.grid_vertices
        a, b = g[self.edges[:, 0]], g[self.edges[:, 1]]
        on_plane = np.zeros(len(self.edges), dtype=bool)
        for side in (0, self.grid):
            on_plane |= np.any((a == side) & (b == side), axis=1)
        return {"interior": int((negative & ~on_plane).sum()), "boundary": int((negative & on_plane).sum())}


@dataclass
class RegionParts:
    """A device's dual split per region, and its contacts' areas per vertex, exactly.

    ``names``/``materials`` of the regions, ``element_region`` (per element, mesh order).
    Control-volume parts, one row per (vertex, region) pair, sorted:
    ``volume_vertex``, ``volume_region``, ``volume_exact`` over ``volume_denominator``
    (times the dual's ``volume_factor``, like its control volumes).  Coupling parts, one
    row per (edge, region): ``coupling_edge`` (index into the dual's edges),
    ``coupling_region``, ``coupling_exact`` over ``coupling_denominator`` (times
    ``volume_factor``, like the coefficients).  Contacts: ``contact_names``,
    ``contact_regions``, ``contact_boxes`` (exact texts, device units), the faces
    (``contact_face_nodes``, -1 padded, ``contact_face_contact``), and the area parts per
    (vertex, contact): ``contact_vertex``, ``contact_contact``, ``contact_exact`` over
    ``contact_denominator``, in device units (a device's lengths are rational).
    ``origin``: the device's bounding box's low corner (exact texts), where the grid starts;
    ``boxes``: per region its boxes (six exact texts each, device units): the domain.
    """

    names: tuple[str, ...]
    materials: tuple[str, ...]
    element_region: np.ndarray
    volume_vertex: np.ndarray
    volume_region: np.ndarray
    volume_exact: np.ndarray
    volume_denominator: int
    coupling_edge: np.ndarray
    coupling_region: np.ndarray
    coupling_exact: np.ndarray
    coupling_denominator: int
    contact_names: tuple[str, ...]
    contact_regions: tuple[int, ...]
    contact_boxes: tuple[tuple[str, ...], ...]
    contact_face_nodes: np.ndarray
    contact_face_contact: np.ndarray
    contact_vertex: np.ndarray
    contact_contact: np.ndarray
    contact_exact: np.ndarray
    contact_denominator: int
    volume_factor: float
    origin: tuple = ("0", "0", "0")
    boxes: tuple = ()

    @property
    def volume_part(self) -> np.ndarray:
        return _scaled(self.volume_exact, self.volume_denominator, self.volume_factor)

    @property
    def coupling_part(self) -> np.ndarray:
        return _scaled(self.coupling_exact, self.coupling_denominator, self.volume_factor)

    @property
    def contact_part(self) -> np.ndarray:
        return _scaled(self.contact_exact, self.contact_denominator, 1.0)

    def region_volumes(self) -> list[Fraction]:
        """Each region's control-volume parts summed, as exact multiples of ``volume_factor``."""
        return [Fraction(int(np.sum(self.volume_exact[self.volume_region == r].astype(object))),
                         self.volume_denominator) for r in range(len(self.names))]

    def contact_areas(self) -> list[Fraction]:
        """Each contact's area parts summed, exactly (device units)."""
        return [Fraction(int(np.sum(self.contact_exact[self.contact_contact == c].astype(object))),
                         self.contact_denominator) for c in range(len(self.contact_names))]


def _lcm_denominator(values) -> int:
    return math.lcm(1, *(v.denominator for v in values))


class _Shape:
    """The pieces of one element shape (or one configuration), keyed by local node ids, as integer arrays."""

    __slots__ = ("edges", "edge_q", "volume_nodes", "volume_q", "boundary")

    def __init__(self, pieces_list: list[ElementPieces]):
        edges: dict[tuple[int, int], Fraction] = {}
        volumes: dict[int, Fraction] = {}
        boundary: dict[tuple[int, Fraction, int], Fraction] = {}
        for pieces in pieces_list:
            for key, q in pieces.edges.items():
                edges[key] = edges.get(key, Fraction(0)) + q
            for node, q in pieces.volumes.items():
                volumes[node] = volumes.get(node, Fraction(0)) + q
            for (axis, value), shares in pieces.boundary.items():
                for node, q in shares.items():
                    boundary[axis, value, node] = boundary.get((axis, value, node), Fraction(0)) + q
        keys = sorted(edges)
        self.edges = np.array(keys, dtype=np.int64).reshape(-1, 2)
        self.edge_q = [edges[k] for k in keys]
        nodes = sorted(volumes)
        self.volume_nodes = np.array(nodes, dtype=np.int64)
        self.volume_q = [volumes[n] for n in nodes]
        self.boundary = sorted(boundary.items())


def _integers(values: list[Fraction], denominator: int) -> np.ndarray:
    return np.array([int(v * denominator) for v in values], dtype=object)


def mesh_dual(mesh, elements: tuple[np.ndarray, np.ndarray] | None = None) -> Dual:
    """The exact dual of a mesh.

    By default the elements are the elements of the mesh's leaf tessellations, and their pieces
    are computed once per configuration, and the cells that replace leaves (global
    Delaunay mode) once per shape.  ``elements`` (``(connectivity, sizes)`` as
    :meth:`Mesh.connectivity` gives them, global vertex ids) takes any element list
    on the mesh's vertices instead, for example cells that span leaves: each element
    is then measured from its vertices (faces: the hull of its nodes; centre: the
    sphere through them), once per distinct shape up to translation and scaling by
    powers of two.
    """
    box = mesh.box
    grid = int(mesh.grid)
    squared = tuple(Fraction(x) for x in box.squared)
    factor_squared = squared[0] * squared[1] * squared[2]
    verts = np.asarray(mesh.vertices, dtype=np.int64)
    n_vertices = len(verts)
    # per group: its pieces, the array and rows that give its members' global vertex ids, their sizes
    if elements is None:
        groups, centers = _leaf_groups(mesh, squared)
        if mesh.cells is not None:
            groups += _cell_groups(mesh, squared, centers)
        elements = mesh.connectivity()
    else:
        groups, centers = _element_groups(mesh, squared, *elements)
    cden = math.lcm(1, *(_lcm_denominator(shape.edge_q) for shape, _, _, _ in groups))
    vden = math.lcm(1, *(_lcm_denominator(shape.volume_q) for shape, _, _, _ in groups))
    bden = math.lcm(1, *(_lcm_denominator([q for _, q in shape.boundary]) for shape, _, _, _ in groups))
    max_size = max((int(sizes.max()) for _, _, _, sizes in groups if len(sizes)), default=1)
    # int64 sums while every product and sum is bounded below 2**62: the largest numerator (not just the
    # denominator: on tiny or huge domains the pieces over a*b*c are far from 1) times the size scaling,
    # times a bound on the pieces met by one edge or vertex
    largest_coefficient = max((abs(int(q * cden)) for shape, _, _, _ in groups for q in shape.edge_q), default=0)
    largest_volume = max((abs(int(q * vden)) for shape, _, _, _ in groups for q in shape.volume_q), default=0)
    largest_boundary = max((abs(int(q * bden)) for shape, _, _, _ in groups for _, q in shape.boundary), default=0)
    wide = largest_volume * max_size ** 3 * 4096 >= 2**62 or largest_coefficient * max_size * 4096 >= 2**62 or \
        largest_boundary * max_size ** 2 * 4096 >= 2**62
    dtype = object if wide else np.int64
    edges, coefficient_exact = _edge_sums(groups, n_vertices, cden, dtype)
    boundary = np.any((verts == 0) | (verts == grid), axis=1)
    volume_exact = np.zeros(n_vertices, dtype=dtype)
    boundary_exact = np.zeros((n_vertices, 3), dtype=dtype)  # per axis: the area in the sides normal to it
    for shape, source, rows, sizes in groups:
        q = _integers(shape.volume_q, vden).astype(dtype)
        touching = []  # the members with a vertex on the domain's boundary: only they have boundary areas
        for part in _chunks(len(rows), len(shape.volume_nodes)):
            ids = source[rows[part, None], shape.volume_nodes]
            # integer sums, unbuffered: exact in any order
            np.add.at(volume_exact, ids, sizes[part, None].astype(dtype) ** 3 * q)
            if shape.boundary:
                touching.append(part.start + np.flatnonzero(boundary[ids].any(axis=1)))
        touching = np.concatenate(touching) if touching else np.zeros(0, dtype=np.int64)
        for (axis, value, node), q in shape.boundary:
            ids = source[rows[touching], node].astype(np.int64)
            on = (verts[ids, axis] == 0) | (verts[ids, axis] == grid)
            # the face lies in the vertex's plane: on the boundary where that plane is a side of the domain
            np.add.at(boundary_exact[:, axis], ids[on], sizes[touching][on].astype(dtype) ** 2 * int(q * bden))
    lengths = np.array(box.to_float())
    real = verts * (lengths / grid)
    factor = math.sqrt(factor_squared)
    coefficient = _scaled(coefficient_exact, cden * grid, factor)
    length = np.empty(len(edges))
    for part in _chunks(len(edges), 1):
        edge_vectors = real[edges[part, 1]] - real[edges[part, 0]]
        length[part] = np.sqrt((edge_vectors ** 2).sum(axis=1))
    control_volume = _scaled(volume_exact, vden * grid ** 3, factor)
    plane_squared = tuple(squared[(k + 1) % 3] * squared[(k + 2) % 3] for k in range(3))
    return Dual(box=box, grid=grid, grid_vertices=verts, vertices=real, edges=edges, length=length,
                area=coefficient * length, coefficient=coefficient, control_volume=control_volume, boundary=boundary,
                boundary_area=boundary_areas(boundary_exact, bden * grid ** 2, plane_squared),
                coefficient_exact=coefficient_exact, coefficient_denominator=cden * grid, volume_exact=volume_exact,
                volume_denominator=vden * grid ** 3, volume_factor=factor, volume_factor_squared=factor_squared,
                boundary_area_exact=boundary_exact, boundary_area_denominator=bden * grid ** 2,
                boundary_factors_squared=plane_squared, element_circumcenter=centers,
                element_nodes=elements[0], element_sizes=elements[1])


def boundary_areas(exact: np.ndarray, denominator: int, factors_squared) -> np.ndarray:
    """The boundary areas as floats from their exact per-axis numerators (see :class:`Dual`)."""
    factors = np.array([math.sqrt(f) for f in factors_squared])
    if exact.dtype == object:  # numbers past float's range (extreme boxes): divided as Python integers first
        return (_scaled(exact.reshape(-1), denominator, 1.0).reshape(exact.shape) * factors).sum(axis=1)
    return (exact.astype(np.float64) * factors).sum(axis=1) / denominator


_CHUNK = 1 << 21  # instances per block of work: its temporaries stay small and the allocator reuses them
PACKED_BITS = 63  # an edge instance's key and payload share one int64 while they fit in these bits


def _chunks(count: int, width: int):
    """Slices of ``range(count)`` of about ``_CHUNK`` / ``width`` rows each."""
    step = max(1, _CHUNK // max(width, 1))
    for start in range(0, count, step):
        yield slice(start, min(start + step, count))


def _edge_sums(groups, n_vertices: int, cden: int, dtype) -> tuple[np.ndarray, np.ndarray]:
    """The mesh's edges (m x 2, ``i < j``, sorted) and their summed coefficient numerators.

    Every edge instance (one edge of one group member) becomes an int64 key
    ``i * 2**v + j`` and a payload: its piece's index into the groups' numerators and
    its member's size as a power of two (coefficients scale with the size).  While key
    and payload fit one int64 together they are sorted as one array (a plain sort,
    several times faster than an argsort, which needs no second array to follow it);
    else the keys are argsorted and the payloads follow.  Equal keys are then runs,
    summed in integers: exact in any order.
    """
    table, offsets, total, max_shift = [], [], 0, 0
    for shape, _, rows, sizes in groups:
        offsets.append(len(table))
        table.extend(int(q * cden) for q in shape.edge_q)
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
            ids = rows[part, None]
            a = source[ids, shape.edges[:, 0]].astype(np.int64)
            b = source[ids, shape.edges[:, 1]].astype(np.int64)
            key = (np.minimum(a, b) << vertex_bits) | np.maximum(a, b)
            payload = pieces | shifts[part, None]
            end = at + key.size
            if packed:
                keys[at:end] = ((key << payload_bits) | payload).reshape(-1)
            else:
                keys[at:end], payloads[at:end] = key.reshape(-1), payload.reshape(-1)
            at = end
    key_shift = payload_bits if packed else 0
    if packed:
        keys.sort()
    else:
        order = np.argsort(keys)
        keys, payloads = keys[order], payloads[order]
        del order
    starts = np.ones(total, dtype=bool)
    for part in _chunks(total - 1, 1):
        starts[part.start + 1:part.stop + 1] = (keys[part.start + 1:part.stop + 1] >> key_shift) != (
            keys[part] >> key_shift)
    first = np.flatnonzero(starts)
    del starts
    unique = np.right_shift(keys[first], key_shift)
    edges = np.empty((len(first), 2), dtype=np.int64)
    np.right_shift(unique, vertex_bits, out=edges[:, 0])
    np.bitwise_and(unique, (1 << vertex_bits) - 1, out=edges[:, 1])
    del unique
    numerators = np.array(table, dtype=dtype)
    powers = np.array([1 << k for k in range(max_shift + 1)], dtype=dtype)
    sums = np.empty(len(first), dtype=dtype)
    # blocks of whole runs, so that each run is summed within one block
    bounds = np.unique(np.r_[np.searchsorted(first, np.arange(0, total, _CHUNK)), len(first)])
    for lo, hi in zip(bounds[:-1], bounds[1:]):
        start, stop = first[lo], first[hi] if hi < len(first) else total
        payload = payloads[start:stop] & ((1 << payload_bits) - 1)
        parts = numerators[payload >> shift_bits] * powers[payload & ((1 << shift_bits) - 1)]
        sums[lo:hi] = np.add.reduceat(parts, first[lo:hi] - start)
    return edges, sums
def _scaled(exact: np.ndarray, den: int, factor: float) -> np.ndarray:
    """``exact / den * factor`` as floats.  Python integers (extreme boxes: 1e-12 x 1 x 3e9 gives numerators
    and denominators past float's range) are divided exactly first, Python's int / int rounding once."""
    if exact.dtype != object:
        return exact.astype(np.float64) * (factor / float(den))
    return np.array([x / den for x in exact.tolist()], dtype=np.float64) * factor


def _leaf_groups(mesh, squared):
    """Per configuration: its pieces, the slots and its leaves (their rows of global vertex ids), their sizes."""
    sizes = mesh.leaf_size()
    lengths = np.array(mesh.box.to_float())
    origin = mesh.tree.positions.astype(np.int64) * sizes[:, None]
    centers = np.zeros((len(mesh), 3))
    groups = []
    for _, tessellation, leaves in mesh.groups():
        first, low, size = mesh.element_offsets[leaves], origin[leaves], sizes[leaves, None]
        for j, element in enumerate(tessellation.elements):
            if element.center is None:
                raise InputError(f"configuration {tessellation.code}: element {j} is not co-spherical: it has no dual")
            centers[first + j] = (low + np.array([float(x) for x in element.center]) * size) * (lengths / mesh.grid)
        groups.append((_tessellation_shape(tessellation, squared), mesh.slots, leaves, sizes[leaves]))
    return groups, centers


def _cell_groups(mesh, squared, centers: np.ndarray):
    """Per shape of the cells that replace leaves: its pieces (grid units, scale 1), its rows of the cells' vertex
    ids; fills ``centers``."""
    cells = mesh.cells
    lengths = np.array(mesh.box.to_float())
    groups = []
    for s, shape in enumerate(cells.shapes):
        rows = np.flatnonzero(cells.shape == s)
        points = {n: tuple(Fraction(x) for x in o) for n, o in enumerate(shape.offsets)}
        pieces = _Shape([element_pieces(points, shape.faces, shape.center, squared)])
        groups.append((pieces, cells.nodes, rows, np.ones(len(rows), dtype=np.int64)))
        centers[mesh.leaf_elements + rows] = (cells.anchor[rows] + np.array([float(x) for x in shape.center])) * (
            lengths / mesh.grid)
    return groups


_SHAPES: dict[tuple, _Shape] = {}


def _tessellation_shape(tessellation, squared) -> _Shape:
    """A configuration's pieces, remembered by its code, box and element node lists (meshes share them)."""
    key = (tessellation.code, squared, tuple(e.nodes for e in tessellation.elements))
    shape = _SHAPES.get(key)
    if shape is None:
        points = tessellation.configuration.nodes()
        shape = _SHAPES[key] = _Shape([element_pieces({n: points[n] for n in e.nodes}, e.faces, e.center, squared)
                                       for e in tessellation.elements])
    return shape


def _element_groups(mesh, squared, conn: np.ndarray, element_sizes: np.ndarray):
    """Per distinct element shape (up to translation and powers of two): its pieces, vertex ids, scalings."""
    verts = np.asarray(mesh.vertices, dtype=np.int64)
    lengths = np.array(mesh.box.to_float())
    centers = np.zeros((len(conn), 3))
    by_shape: dict[tuple, tuple[_Shape, list, list]] = {}
    for e in range(len(conn)):
        ids = conn[e, :int(element_sizes[e])].astype(np.int64)
        coords = verts[ids]
        low = coords.min(axis=0)
        rel = coords - low
        scale = math.gcd(*(int(x) for x in rel.reshape(-1)))
        scale = scale & -scale  # the largest power of two dividing every offset
        key = tuple(map(tuple, (rel // scale).tolist()))
        entry = by_shape.get(key)
        if entry is None:
            points = {n: tuple(Fraction(int(x)) for x in p) for n, p in enumerate(key)}
            frame = Frame.build(points, squared)
            element = measure(frame, range(len(key)))
            if not element.cycles:
                raise InputError(f"element {e} is flat: it has no dual")
            if element.sphere is None:
                raise InputError(f"element {e} is not co-spherical: it has no dual")
            center = element.center
            entry = by_shape[key] = (_Shape([element_pieces(points, element.cycles, center, squared)]), [], [],
                                     center)
        entry[1].append(ids)
        entry[2].append(scale)
        centers[e] = (low + np.array([float(x) for x in entry[3]]) * scale) * (lengths / mesh.grid)
    groups = [(shape, np.array(ids, dtype=np.int64), np.arange(len(ids)), np.array(scales, dtype=np.int64))
              for shape, ids, scales, _ in by_shape.values()]
    return groups, centers


TETRAHEDRAL_LIMIT = 1_000_000  # vertices: above it the tetrahedral comparison is skipped (minutes and gigabytes)


def external_tetrahedra(grid_vertices: np.ndarray) -> tuple[np.ndarray, str, int]:
    """A tetrahedral Delaunay mesh of integer points by an outside mesher: (tetrahedra, the tool, flat ones left out).

    TetGen (``tetgen``, Debian; exact predicates) when it is installed; else scipy's
    Qhull, whose flat tetrahedra (co-spherical points it triangulates through a
    zero-volume sliver, decided on the integers) are left out and counted.
    """
    import shutil
    import subprocess
    import tempfile

    points = np.asarray(grid_vertices, dtype=np.int64)
    tool = shutil.which("tetgen")
    if tool:
        with tempfile.TemporaryDirectory() as folder:
            node = Path(folder) / "points.node"
            rows = np.column_stack([np.arange(len(points)), points])
            try:
                with open(node, "w") as handle:
                    handle.write(f"{len(points)} 3 0 0\n")
                    np.savetxt(handle, rows, fmt="%d")
            except OSError as error:  # a write that fails (a full disk) names no file: name the scratch file
                raise OSError(error.errno, error.strerror, str(node)) from None
            subprocess.run([tool, "-Q", "-F", "-N", str(node)], check=True, capture_output=True, timeout=3600)
            tets = np.loadtxt(Path(folder) / "points.1.ele", dtype=np.int64, skiprows=1, ndmin=2)[:, 1:5]
        return tets, "tetgen", 0
    from scipy.spatial import Delaunay

    tets = Delaunay(points.astype(np.float64)).simplices.astype(np.int64)
    keep = six_volumes(points[tets]) != 0
    return tets[keep], "qhull", int((~keep).sum())


def tetrahedral_counts(grid_vertices: np.ndarray) -> dict:
    """Elements, edges, faces and matrix nonzeros of a tetrahedral Delaunay mesh of the same vertices.

    The paper's claim is that mixed elements need fewer of each; this is the
    tetrahedral side of that comparison (:func:`external_tetrahedra`).
    """
    points = np.asarray(grid_vertices, dtype=np.int64)
    tets, tool, flat = external_tetrahedra(points)
    tets = np.sort(tets, axis=1)
    n = np.int64(len(points))
    pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    edges = distinct(np.concatenate([tets[:, a] * n + tets[:, b] for a, b in pairs]))
    triples = [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)]
    faces = distinct(np.concatenate([(tets[:, a] * n + tets[:, b]) * n + tets[:, c] for a, b, c in triples]))
    return {"tool": tool, "elements": int(len(tets)), "edges": int(len(edges)),
            "faces": int(len(faces)), "nonzeros": int(len(points) + 2 * len(edges)), "flat": flat}


def dual_summary(dual: Dual, elements: int, faces: int, tetrahedral: bool = True) -> dict:
    """The report's figures of a dual: negative coefficients, sums, and the mixed mesh beside a tetrahedral one.

    ``elements`` and ``faces`` are the mixed mesh's (faces: interior plus boundary);
    ``tetrahedral=False``, or more than :data:`TETRAHEDRAL_LIMIT` vertices, leaves the
    tetrahedral side ``None``.
    """
    negative = dual.negative_coefficients()
    mixed = {"elements": int(elements), "edges": int(len(dual.edges)), "faces": int(faces),
             "nonzeros": int(len(dual.vertices) + 2 * len(dual.edges))}
    tets = tetrahedral_counts(dual.grid_vertices) if tetrahedral and len(dual.vertices) <= TETRAHEDRAL_LIMIT else None
    return {"negative_coefficients": negative, "dual": {
        "edges": mixed["edges"], "volume_sum": str(dual.volume_sum()),
        "coefficient_min": float(dual.coefficient.min()) if len(dual.edges) else None,
        "coefficient_max": float(dual.coefficient.max()) if len(dual.edges) else None,
        "boundary_vertices": int(dual.boundary.sum()), "mixed": mixed, "tetrahedral": tets}}
