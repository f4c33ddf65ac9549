"""The global Delaunay (empty-sphere) check: no mesh vertex strictly inside any element's circumsphere.

A leaf's sphere can hold a vertex of a smaller neighbour, so no per-leaf test can replace
this one: it is decided on the global vertex set.  Exactly: every vertex that could lie on or in an element's sphere
is found, and each is decided with the integer in-sphere test of the element's
configuration frame (the same predicate as the tessellation's), so every violation
and every tie is decided exactly.  Two ways find them:

- By the tree's structure, for the leaf elements of a full tree whose leaves
  touching at a face, an edge or a corner differ by at most one level
  (:attr:`~cospherical.mesh.octree.Octree.vertex_balanced`).  Let B be a leaf of side
  s (per axis) and d the L-infinity distance from B in units of s.  Then the
  vertices with d = 0 are B's slots (the leaves touching B are at least s/2, so
  their corners on B are the 27 half-spacing points, and no vertex is inside a
  leaf); none has 0 < d < 1/2, and those with 1/2 <= d < 3/4 are points of the
  lattice of spacing s/4 aligned with B.  Proof: a vertex is a corner of some leaf
  T; if T is at least s/4 its corners are on that lattice, and at least s/2 puts
  them at d = 0 or d >= 1/2.  A T of side s/4 with a corner at 0 < d < 1/2 has a
  parent cell (side s/2) within d < 1/2 of B, hence touching B, split into leaves
  of at most s/4, one of which touches B: two levels apart.  Otherwise T (at most
  s/8) lies in a cell C of side s/4 of the aligned grid, split, within d <= 1/2 of B.  If C's parent cell (side
  s/2) touches B, that parent is split into leaves of at most s/4, one of which
  touches B: two levels apart.  If not, C touches a cell of side s/2 that touches B,
  and that cell lies in one leaf of at least s/2 (or leaves under s/2 would touch
  B); a leaf in C of at most s/8 touches it: two levels apart again.  So for an
  element whose closed sphere stays within d < 3/4 (decided exactly, once per
  configuration, in the leaf's unit frame: every leaf is the domain scaled), the
  only vertices that can lie on or in it are its leaf's other slots in the sphere
  and the lattice points with d = 1/2 in the sphere that are vertices: a handful
  of exact look-ups per leaf (:func:`_local_candidates`), no search.  The proof
  reads only the whole tree's structure: a part of its leaves (a device keeps those
  inside its boxes, a region's mesh those of the region) has a part of its vertices,
  each where the whole tree has it, so the look-ups still find every vertex that
  can be on or in a sphere.
- Otherwise (a cell of the global Delaunay step, a sphere reaching further, a
  leaf list only checked 1-irregular, a piece's
  surroundings), a k-d tree on the vertices' float coordinates proposes the
  vertices within the circumradius times (1 + 1e-9) (:func:`_candidates`); the
  element's own nodes are expected there and anything else is decided exactly:
  the float slack only widens the net.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Callable, NamedTuple, Sequence

import numpy as np
from numpy.typing import NDArray

from ...core.morton import morton_codes
from ...errors import InputError
from ..assembly import LocalElement, LocalTessellation, Mesh
from ..report_sections import LeafMeshSummary
from ..tree import distinct


# Vertices found near spheres and tested exactly, at most: each test is a few microseconds of
# Python integers and its pair ~100 bytes. A 1.38 M-leaf sphere tree needs 2.5 M; a box of
# lengths 1e-12 x 1 x 3e9 at level 5 needed 40.6 M (floats there cannot separate the vertices
# near a sphere), and at level 6 it passed 19.5 GB before the kernel killed it.
_MAX_EXACT_TESTS = 1 << 24
_PAIR_CHUNK = 1 << 22

__all__ = ["DelaunayCheck", "check_delaunay", "grid_weights"]


@dataclass(frozen=True, eq=False)
class DelaunayCheck:
    """What :func:`check_delaunay` found on a mesh: the report's counts and the elements behind them.

    Attributes
    ----------
    violations : int
        Elements whose circumsphere strictly holds a mesh vertex (the report's ``delaunay_violations``).
    violating_pairs : int
        (element, vertex) pairs with the vertex strictly inside the element's sphere.
    violating_leaves : int
        Leaves holding a violating element (or giving up their place to a violating cell).
    ties : int
        (element, vertex) pairs with a vertex of another element on the sphere: the two could merge.
    exact_tests : int
        (element, vertex) pairs decided with integers.
    violating_leaf_ids : numpy.ndarray
        The violating leaves' indices, sorted.
    violating_elements : numpy.ndarray
        The violating elements' indices, sorted (the report's ``delaunay_ok`` cell data).
    not_cells : numpy.ndarray
        The elements that violate, tie or have no sphere, sorted: those that are not cells of the
        Delaunay subdivision of the vertices, which :func:`~cospherical.mesh.delaunay.global_delaunay`
        replaces.
    bounded, searched : int
        Spheres whose candidate vertices came from the tree's structure (see the module
        docstring), and spheres whose came from a k-d tree's search.
    """

    violations: int
    violating_pairs: int
    violating_leaves: int
    ties: int
    exact_tests: int
    violating_leaf_ids: NDArray[np.int64]
    violating_elements: NDArray[np.int64]
    not_cells: NDArray[np.int64]
    bounded: int = 0
    searched: int = 0

    def figures(self) -> dict[str, int]:
        """The counts as the report names them (``delaunay_violations``, ...), in its order."""
        return {"delaunay_violations": self.violations, "delaunay_violating_pairs": self.violating_pairs,
                "delaunay_violating_leaves": self.violating_leaves, "delaunay_ties": self.ties,
                "delaunay_exact_tests": self.exact_tests}

    def leaf_mesh(self, elements: int) -> LeafMeshSummary:
        """The report's ``leaf_mesh`` figures of a leaf mesh of ``elements`` elements that this check found."""
        return LeafMeshSummary(elements, self.violations, self.ties, int(len(self.not_cells)))


def check_delaunay(mesh: Mesh, workers: int = 2, progress: Callable[[int], None] | None = None) -> DelaunayCheck:
    """No mesh vertex strictly inside any element's circumsphere, decided exactly.

    Returns a :class:`DelaunayCheck`: the counts of violations and ties and the elements
    that are not cells of the Delaunay subdivision of the vertices.  Four steps: every
    element's sphere (:func:`_spheres`), the vertices that can lie on or in each (by the
    tree's structure, :func:`_local_candidates`, else those floats find near it,
    :func:`_candidates`, a k-d tree), each of those decided exactly (:func:`_exact_sides`),
    and what the signs say (:func:`_found`).

    In a mesh with re-tessellated cells (:func:`~cospherical.mesh.delaunay.global_delaunay`)
    the leaf elements and the cells marked ``proven`` passed this check on the same
    vertex set when they were kept, so only the other cells are tested (and counted in
    ``delaunay_exact_tests``); ``progress`` is told of the others at once.
    """
    spheres, local = _spheres(mesh)
    local_row, local_vertex = _local_candidates(mesh, local)
    if progress:
        progress(len(mesh) - len(spheres.searched))
    if not len(spheres.tessellation):
        none = np.zeros(0, dtype=np.int64)
        return DelaunayCheck(0, 0, 0, 0, 0, none, none, spheres.without_sphere)
    pair_row, pair_vertex = local_row, local_vertex
    if len(spheres.searched):
        found_row, found_vertex = _candidates(mesh, mesh.points(), spheres, workers, progress)
        pair_row, pair_vertex = np.r_[pair_row, found_row], np.r_[pair_vertex, found_vertex]
    return _found(mesh, spheres, pair_row, _exact_sides(mesh, spheres, pair_row, pair_vertex),
                  (len(spheres.tessellation) - len(spheres.searched), len(spheres.searched)))


class _Spheres(NamedTuple):
    """The spheres :func:`check_delaunay` tests, one row each: a leaf element's or a fresh cell's.

    ``tessellation``: the leaf's tessellation (-1: a cell); ``local``: the element in it (a
    cell: its shape); ``leaf``: the leaf (a cell: its index among the cells); ``nodes``: the
    element's vertex count; ``searched``: the rows whose vertices a k-d tree finds, and for
    them ``centers`` and ``radii`` in real units (floats: they only propose);
    ``without_sphere``: the leaf elements that have none (not co-spherical), sorted.
    """

    tessellation: np.ndarray
    local: np.ndarray
    leaf: np.ndarray
    nodes: np.ndarray
    searched: np.ndarray
    centers: np.ndarray
    radii: np.ndarray
    without_sphere: np.ndarray


class _Suspects(NamedTuple):
    """What can lie on or in a leaf element's closed sphere besides its nodes (see the module docstring).

    ``slots``: the leaf's other slots in it; ``lattice``: (m, 3) int64, the points of the
    lattice of spacing a quarter leaf, at L-infinity distance half a leaf from it, in it
    (in quarters of the leaf, from its low corner).
    """

    slots: tuple[int, ...]
    lattice: np.ndarray


# The lattice of quarter leaves around a leaf (in quarters, the leaf is 0..4 on each axis), at half a
# leaf from it (L-infinity): where vertices beside a leaf's own slots can lie within 3/4 of a leaf
_QUARTERS = np.array(list(itertools.product(range(-3, 8), repeat=3)), dtype=np.int64)
_HALF_A_LEAF_OUT = _QUARTERS[np.maximum(np.maximum(-_QUARTERS, _QUARTERS - 4), 0).max(axis=1) == 2]


def _leaf_suspects(tessellations: Sequence[LocalTessellation], squared: tuple[Fraction, Fraction, Fraction]
                   ) -> list[list[_Suspects | None]]:
    """Per configuration, per element, its :class:`_Suspects`, or ``None`` when its closed sphere reaches 3/4 of
    a leaf beyond the leaf on some axis (or it has none): decided exactly in the leaf's unit frame, where the
    squared distance is the sum over the axes of ``squared[k]`` (the box's squared lengths) times the squared
    difference.  Every configuration's elements at once, in integer coordinates of one common scale (the
    verdicts are comparisons of squared distances: the same at any scale).
    """
    scale_w = math.lcm(*(w.denominator for w in squared))
    weights = [int(w * scale_w) for w in squared]
    nodes = [tessellation.configuration.nodes() for tessellation in tessellations]
    measured: list[tuple[int, int, LocalElement]] = []  # (configuration, element, the element) with a centre
    exact: list[tuple[Fraction, Fraction, Fraction]] = []  # their centres
    for t, tessellation in enumerate(tessellations):
        for j, element in enumerate(tessellation.elements):
            if element.center is not None:
                measured.append((t, j, element))
                exact.append(element.center)
    found: list[list[_Suspects | None]] = [[None] * len(tessellation.elements) for tessellation in tessellations]
    if not measured:
        return found
    # integer coordinates: unit coordinates times m (a multiple of 4, so the lattice's quarters are whole)
    m = math.lcm(4, *(c.denominator for center in exact for c in center),
                 *(x.denominator for points in nodes for point in points.values() for x in point))

    def scaled(point: Sequence[int | Fraction]) -> list[int]:
        return [x.numerator * (m // x.denominator) for x in point]

    centers = [scaled(center) for center in exact]
    # int64 when every term is below 2**61 (the lattice reaches 7/4 of the leaf), else Python integers
    reach = max(abs(x) for center in centers for x in center)
    kind = np.int64 if max(weights) * (2 * m + reach) ** 2 < 2**61 else object
    center_array = np.array(centers, dtype=kind)  # elements x 3
    weight_array = np.array(weights, dtype=kind)
    # each configuration's 27 slots (node ids 0..26), those it has
    slots = np.zeros((len(tessellations), 27, 3), dtype=kind)
    present = np.zeros((len(tessellations), 27), dtype=bool)
    for t, points in enumerate(nodes):
        for n, point in points.items():
            slots[t, n] = scaled(point)
            present[t, n] = True
    owner = np.array([t for t, _, _ in measured], dtype=np.intp)

    def squared_distances(points: np.ndarray) -> np.ndarray:
        """elements x points: the squared distances of ``points`` (elements x n x 3: each element's own,
        scaled) from each element's centre."""
        offsets = points - center_array[:, None, :]
        distances: np.ndarray = (offsets * offsets * weight_array).sum(axis=2)
        return distances

    to_slots = squared_distances(slots[owner])
    # the lattice's points have 11 coordinates an axis: per axis, each element's terms for those 11, then
    # each point's three terms added (the same integers as a point-by-point sum, in a fraction of the time)
    quarters = np.arange(-3, 8).astype(kind) * (m // 4)
    terms = [weight_array[k] * (quarters[None, :] - center_array[:, k:k + 1]) ** 2 for k in range(3)]
    at = _HALF_A_LEAF_OUT + 3  # the points' coordinates as indices into the 11
    to_lattice = terms[0][:, at[:, 0]] + terms[1][:, at[:, 1]] + terms[2][:, at[:, 2]]
    radius2 = to_slots[np.arange(len(measured)), [e.nodes[0] for _, _, e in measured]][:, None]
    # the sphere's extent on each axis, from its centre: strictly inside -3/4 .. 7/4 of the leaf
    low, high = center_array + 3 * m // 4, 7 * m // 4 - center_array
    inside = ((low > 0) & (high > 0) & (radius2 < weight_array * low * low)
              & (radius2 < weight_array * high * high)).all(axis=1).tolist()
    near = ((to_slots <= radius2) & present[owner]).tolist()
    in_lattice = to_lattice <= radius2
    for row, (t, j, element) in enumerate(measured):
        if inside[row]:
            own = set(element.nodes)
            found[t][j] = _Suspects(tuple(n for n, hit in enumerate(near[row]) if hit and n not in own),
                                    _HALF_A_LEAF_OUT[in_lattice[row]])
    return found


def _spheres(mesh: Mesh) -> tuple[_Spheres, list[tuple[int, np.ndarray, _Suspects]]]:
    """Every sphere to test: each leaf element's (a mesh without cells), else each fresh cell's; and, for the
    rows whose candidates the tree's structure gives, (first row, leaves, suspects) per block of alike rows.

    The leaf elements kept beside re-tessellated cells, and the cells marked proven, passed
    this very check on the same vertex set when they were chosen: only the other cells are
    tested again.
    """
    grid = mesh.grid
    scale = np.array(mesh.box.to_float()) / grid
    size = grid >> mesh.tree.levels.astype(np.int64)
    origin = mesh.tree.positions.astype(np.int64) * size[:, None]
    points = None
    rows_tessellation, rows_local, rows_leaf, n_nodes, searched, centers, radii = [], [], [], [], [], [], []
    local: list[tuple[int, np.ndarray, _Suspects]] = []
    rows = 0
    # A table element that is not co-spherical (a table may hold one) has no sphere to test, and
    # is not a cell of the Delaunay subdivision: it joins the elements that are not cells.
    without_sphere = [np.zeros(0, dtype=np.int64)]
    cells = mesh.cells
    structured = mesh.tree.vertex_balanced
    groups = list(mesh.groups()) if cells is None else []
    every = _leaf_suspects([tessellation for _, tessellation, _ in groups], mesh.box.squared) if structured else None
    for g, (p, tessellation, leaves) in enumerate(groups):
        suspects = every[g] if every is not None else [None] * len(tessellation.elements)
        for j, element in enumerate(tessellation.elements):
            if element.sphere is None or element.center is None:  # check_circumcenters: not co-spherical
                without_sphere.append(mesh.element_offsets[leaves].astype(np.int64) + j)
                continue
            rows_tessellation.append(np.full(len(leaves), p, dtype=np.int32))
            rows_local.append(np.full(len(leaves), j, dtype=np.int16))
            rows_leaf.append(leaves.astype(np.int64))
            n_nodes.append(np.full(len(leaves), len(element.nodes), dtype=np.int64))
            suspect = suspects[j]
            if suspect is not None:
                local.append((rows, leaves, suspect))
            else:
                points = mesh.points() if points is None else points
                center = (origin[leaves] + np.array([float(x) for x in element.center])[None]
                          * size[leaves, None]) * scale
                first = points[mesh.slots[leaves, element.nodes[0]]]
                searched.append(np.arange(rows, rows + len(leaves)))
                centers.append(center)
                radii.append(np.sqrt(((first - center) ** 2).sum(axis=1)))
            rows += len(leaves)
    if cells is not None and len(cells):
        points = mesh.points()
        # a cell is a row of tessellation -1 whose "leaf" is its index among the cells
        fresh = np.flatnonzero(~cells.proven)
        fresh = fresh[np.argsort(cells.shape[fresh], kind="stable")]
        starts = np.searchsorted(cells.shape[fresh], np.arange(len(cells.shapes) + 1))
        for s, shape in enumerate(cells.shapes):
            chosen = fresh[starts[s]:starts[s + 1]]
            center = (cells.anchor[chosen] + np.array([float(x) for x in shape.center])[None]) * scale
            first = points[cells.nodes[chosen, 0]]
            rows_tessellation.append(np.full(len(chosen), -1, dtype=np.int32))
            rows_local.append(np.full(len(chosen), s, dtype=np.int16))
            rows_leaf.append(chosen.astype(np.int64))
            n_nodes.append(np.full(len(chosen), len(shape.offsets), dtype=np.int64))
            searched.append(np.arange(rows, rows + len(chosen)))
            centers.append(center)
            radii.append(np.sqrt(((first - center) ** 2).sum(axis=1)))
            rows += len(chosen)

    def joined(parts: list[np.ndarray], empty: np.ndarray) -> np.ndarray:
        return np.concatenate(parts) if parts else empty

    none = np.zeros(0, dtype=np.int64)
    return _Spheres(joined(rows_tessellation, none.astype(np.int32)), joined(rows_local, none.astype(np.int16)),
                    joined(rows_leaf, none), joined(n_nodes, none), joined(searched, none),
                    joined(centers, np.zeros((0, 3))), joined(radii, np.zeros(0)),
                    np.sort(np.concatenate(without_sphere))), local


def _local_candidates(mesh: Mesh, local: list[tuple[int, np.ndarray, _Suspects]]) -> tuple[np.ndarray, np.ndarray]:
    """(sphere row, vertex) pairs to decide exactly for the spheres the tree's structure bounds: per block of
    alike rows (one element of a configuration on its leaves, from ``first`` on), the leaves' slots in the
    sphere and the lattice points in it that are vertices (a grid point's key looked up among the vertices')."""
    if not local:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    grid = mesh.grid
    n = np.int64(grid + 1)
    vertices = mesh.vertices.astype(np.int64)
    keys = (vertices[:, 0] * n + vertices[:, 1]) * n + vertices[:, 2]  # increasing: a vertex's id is its rank
    size = grid >> mesh.tree.levels.astype(np.int64)
    rows_found, vertices_found = [np.zeros(0, dtype=np.int64)], [np.zeros(0, dtype=np.int64)]
    for first, leaves, suspects in local:
        rows = first + np.arange(len(leaves), dtype=np.int64)
        for slot in suspects.slots:
            rows_found.append(rows)
            vertices_found.append(mesh.slots[leaves, slot].astype(np.int64))
        if not len(suspects.lattice):
            continue
        side = size[leaves]
        low = mesh.tree.positions[leaves].astype(np.int64) * side[:, None]
        # (leaves, points, 3): a lattice point is a grid point only where a quarter leaf is whole grid steps
        scaled = suspects.lattice[None] * side[:, None, None]
        at = low[:, None] + scaled // 4
        candidate = ((scaled % 4 == 0) & (at >= 0) & (at <= grid)).all(axis=2)
        which, point = np.nonzero(candidate)
        key = (at[which, point, 0] * n + at[which, point, 1]) * n + at[which, point, 2]
        rank = np.minimum(np.searchsorted(keys, key), len(keys) - 1)
        present = keys[rank] == key
        rows_found.append(rows[which[present]])
        vertices_found.append(rank[present])
    return np.concatenate(rows_found), np.concatenate(vertices_found)


def _candidates(mesh: Mesh, points: np.ndarray, spheres: _Spheres, workers: int,
                progress: Callable[[int], None] | None) -> tuple[np.ndarray, np.ndarray]:
    """(sphere row, vertex) pairs to decide exactly: the vertices that floats put near a sphere, the
    sphere's own nodes left out, for every searched sphere (``spheres.searched``) that does not hold
    exactly its own nodes.

    A k-d tree of the vertices counts those within each sphere's radius (a hair more); the count
    is the element's node count for a sphere with nothing else near it, and only the others
    (the suspects) have their vertices listed and go to the exact test.
    """
    from scipy.spatial import cKDTree

    centers = spheres.centers
    reach = spheres.radii * (1 + 1e-9) + 1e-12 * float(np.abs(points).max())
    # Only vertices in the box around every reach can be within one: the rest are left out of the
    # search (a piece of a partitioned mesh holds all the vertices but searches its surroundings).
    low, high = (centers - reach[:, None]).min(axis=0), (centers + reach[:, None]).max(axis=0)
    lowest, highest = points.min(axis=0), points.max(axis=0)
    near = None  # every vertex (the whole mesh's check): no mask to build
    if (low > lowest).any() or (high < highest).any():
        near = np.flatnonzero(((points >= low) & (points <= high)).all(axis=1))
        if len(near) == len(points):
            near = None
    tree = cKDTree(points if near is None else points[near])
    counts = np.empty(len(centers), dtype=np.int64)
    chunk = 1 << 18
    # the spheres in Morton order: neighbouring queries walk the same branches of the tree (a quarter less CPU)
    nearby = _morton_order(centers, lowest, highest)
    for start in range(0, len(centers), chunk):
        part = nearby[start:start + chunk]
        counts[part] = tree.query_ball_point(centers[part], reach[part], return_length=True, workers=workers)
        if progress:
            progress(len(part))
    # the element's own nodes are on its sphere; anything more (or less) is looked at exactly
    suspect = np.flatnonzero(counts != spheres.nodes[spheres.searched])
    tests = int(counts[suspect].sum())
    if tests > _MAX_EXACT_TESTS:
        raise InputError(f"the exact Delaunay check needs {tests:,} sphere tests, above the bound of "
                         f"{_MAX_EXACT_TESTS:,}: on a box this stretched, floats cannot tell which vertices "
                         "are near each sphere (a coarser tree, or --delaunay leaf --no-delaunay)")
    pairs_row, pairs_vertex = [], []
    # chunks of at most _PAIR_CHUNK vertices found (a Python list of them is 36 bytes a vertex), and
    # at least one sphere each
    ends = np.searchsorted(np.cumsum(counts[suspect]), np.arange(1, tests // _PAIR_CHUNK + 2) * _PAIR_CHUNK, "right")
    for start, end in zip(np.r_[0, ends[:-1]], ends):
        rows = suspect[start:max(end, start + 1)]
        if not len(rows):
            continue
        found = tree.query_ball_point(centers[rows], reach[rows], workers=workers)
        if any(x is None for x in found):  # a search thread that ran out of memory leaves None
            raise MemoryError
        lengths = np.fromiter((len(x) for x in found), dtype=np.int64, count=len(found))
        pairs_row.append(np.repeat(spheres.searched[rows], lengths))
        found_vertices = np.fromiter((v for x in found for v in x), dtype=np.int64, count=int(lengths.sum()))
        pairs_vertex.append(found_vertices if near is None else near[found_vertices])
    pair_row = np.concatenate(pairs_row) if pairs_row else np.zeros(0, dtype=np.int64)
    pair_vertex = np.concatenate(pairs_vertex) if pairs_vertex else np.zeros(0, dtype=np.int64)
    # drop each element's own nodes
    is_cell = spheres.tessellation[pair_row] < 0
    own = np.zeros(len(pair_row), dtype=bool)
    leafy = np.flatnonzero(~is_cell)
    leaf_of_pair = spheres.leaf[pair_row[leafy]]
    nodes = mesh.element_nodes(mesh.element_offsets[leaf_of_pair] + spheres.local[pair_row[leafy]])
    own[leafy] = (nodes == pair_vertex[leafy, None]).any(axis=1)
    celly = np.flatnonzero(is_cell)
    if len(celly):
        own[celly] = (mesh.required_cells().nodes[spheres.leaf[pair_row[celly]]] == pair_vertex[celly, None]).any(axis=1)
    return pair_row[~own], pair_vertex[~own]


def _exact_sides(mesh: Mesh, spheres: _Spheres, pair_row: np.ndarray, pair_vertex: np.ndarray) -> np.ndarray:
    """Per (sphere row, vertex) pair, where the vertex lies against the sphere, decided in integers in the
    element's own frame: -1 strictly inside, 0 on it, 1 outside (int8)."""
    cells = mesh.cells
    size = mesh.grid >> mesh.tree.levels.astype(np.int64)
    origin = mesh.tree.positions.astype(np.int64) * size[:, None]
    sides = np.zeros(len(pair_row), dtype=np.int8)
    weights = grid_weights(mesh)
    rows_tessellation, rows_local, rows_leaf = spheres.tessellation, spheres.local, spheres.leaf
    for i, (row, vertex) in enumerate(zip(pair_row.tolist(), pair_vertex.tolist())):
        if rows_tessellation[row] < 0 and cells is not None:  # a cell's sphere (a mesh with cells)
            shape = cells.shapes[rows_local[row]]
            x = [int(v) - int(o) for v, o in zip(mesh.vertices[vertex], cells.anchor[rows_leaf[row]])]
            side = shape.sphere.side_at(x, weights)
        else:
            tessellation = mesh.tessellations[rows_tessellation[row]]
            element = tessellation.elements[rows_local[row]]
            leaf = rows_leaf[row]
            m = int(size[leaf])
            x = [tessellation.scale * (int(v) - int(o)) for v, o in zip(mesh.vertices[vertex], origin[leaf])]
            side = element.sphere.side_at(x, tessellation.weights, m)
        sides[i] = (side > 0) - (side < 0)
    return sides


def _found(mesh: Mesh, spheres: _Spheres, pair_row: np.ndarray, sides: np.ndarray,
           spheres_by: tuple[int, int]) -> DelaunayCheck:
    """What the exact sides of the (sphere row, vertex) pairs say: the violations, the ties, and the
    elements that are not cells of the Delaunay subdivision (those violating or tying, and those
    without a sphere)."""
    cells = mesh.cells
    rows_tessellation, rows_local, rows_leaf = spheres.tessellation, spheres.local, spheres.leaf
    inside = sides < 0
    bad_rows = distinct(pair_row[inside])

    def elements(rows: np.ndarray) -> np.ndarray:
        cell = rows_tessellation[rows] < 0
        return np.sort(np.where(cell, mesh.leaf_elements + rows_leaf[rows],
                                mesh.element_offsets[np.where(cell, 0, rows_leaf[rows])] + rows_local[rows])
                       ).astype(np.int64)

    leaf_rows = bad_rows[rows_tessellation[bad_rows] >= 0]
    bad_leaves = distinct(np.r_[rows_leaf[leaf_rows], cells.leaf[rows_leaf[bad_rows[rows_tessellation[bad_rows] < 0]]]
                                 if cells is not None else np.zeros(0, dtype=np.int64)])
    not_cells = np.sort(np.r_[elements(distinct(pair_row[sides <= 0])), spheres.without_sphere])
    return DelaunayCheck(int(len(bad_rows)), int(inside.sum()), int(len(bad_leaves)), int((sides == 0).sum()),
                         int(len(pair_row)), bad_leaves, elements(bad_rows), not_cells, *spheres_by)


def _morton_order(points: np.ndarray, low: np.ndarray, high: np.ndarray, bits: int = 10) -> np.ndarray:
    """The order of ``points`` along the Z-order curve of a ``2**bits`` grid on the box ``low``..``high``."""
    cell = np.clip((points - low) * ((1 << bits) / np.maximum(high - low, 1e-300)), 0, (1 << bits) - 1)
    return np.argsort(morton_codes(cell.astype(np.int64)), kind="stable")


def grid_weights(mesh: Mesh) -> tuple[int, int, int]:
    """The box's squared lengths as integers in one ratio: the weights of the grid frame."""
    squared = mesh.box.squared
    den = math.lcm(*(w.denominator for w in squared))
    return int(squared[0] * den), int(squared[1] * den), int(squared[2] * den)
