"""The exact Delaunay subdivision of a mesh's vertex set, from the leaf mesh and a few re-tessellated regions.

Let V be the vertices and D their Delaunay subdivision: each cell the convex hull
of all points of V on one empty sphere, the cells tiling the domain (the convex
hull of V).  The leaf mesh already tiles the domain with elements that are
co-spherical polytopes.

Why the leaf elements that pass the exact global check are kept, and the rest
re-tessellated region by region:

1. An element whose sphere holds no vertex strictly inside and no vertex of V on
   it but its own nodes is a cell of D (that is the definition of a cell).
   :func:`~cospherical.mesh.checks.check_delaunay` decides both exactly; every
   other element violates or ties.
2. Let U be the union of the leaves that hold an element of the second kind.
   Outside U every element is a cell of D, and these cells and the leaves of U tile
   the domain, so U is exactly the union of the cells of D not kept: U is tiled by
   cells of D.  (Whole leaves are taken rather than single elements: a leaf is a
   box, its vertices known at once, and the argument does not care.)
3. Split U into its connected parts U_r (leaves sharing a vertex).  A cell of D is
   convex, so each cell in U lies in one U_r.  Let V_r be the vertices on the
   closure of U_r.  A cell C of D inside U_r is a cell of Del(V_r): its vertices
   are in V_r, its sphere holds no point of V, so none of V_r, and every point of
   V_r on it is in V, hence a vertex of C.
4. The cells of D inside U_r tile U_r and are cells of Del(V_r); cells of Del(V_r)
   do not overlap, so every other cell of Del(V_r) has its interior outside U_r.
   A cell of Del(V_r) is therefore kept exactly when one interior point lies in
   U_r: the centroid of any of its tetrahedra (never on the boundary of U_r, which
   the cell either lies in or does not cross).
So D = the kept leaf elements plus, per region, the cells of Del(V_r) inside U_r.

The engine (chosen by measurement: scipy's Qhull proposes, integers decide):
Qhull's tetrahedra of V_r in floats; every tetrahedron is then measured in
integers on the vertex grid (weights: the squared box lengths), so only the
proposal is inexact.  Flat tetrahedra (exactly zero volume) are dropped; a
tetrahedron is inside U_r when the leaf holding its centroid belongs to U_r
(integer point location); tetrahedra with the same exact circumcenter are one
cell (concentric empty spheres through points cannot differ, so the centre names
the sphere).  Measured against CGAL's exact-predicate triangulation (pip ``cgal``) on
50,000 points at load 11: Qhull 13.1 s in all, CGAL 2.9 s to insert but 13.4 s to
read its cells back through the Python bindings, one object per cell; Qhull hands
back arrays.  A cell's vertices are its tetrahedra's.  The whole mesh is then
checked again by the report (volume, conformity, empty spheres and ties), so a
wrong proposal cannot pass unseen.  Cube octrees, whose leaf mesh is already
globally Delaunay, have no region: the mesh is returned as it is.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from ..core.geometry import Frame
from ..core.tessellation import tessellation_elements
from ..errors import CosphericalError, InputError
from .assembly import CellShape, Cells, Mesh, _type_info
from .checks import _weights, check_delaunay

__all__ = ["MODES", "delaunay_mesh", "global_delaunay", "retessellate", "with_cells"]


def global_delaunay(mesh: Mesh, found: dict | None = None) -> Mesh:
    """The exact Delaunay subdivision of ``mesh``'s vertices, as a :class:`Mesh` (see the module's proof).

    ``found``: the result of :func:`check_delaunay` on ``mesh`` when the caller has it.

    Examples
    --------
    >>> from cospherical.core.configuration import Box
    >>> from cospherical.mesh.assembly import assemble
    >>> from cospherical.mesh.octree import build_octree, parse_shape
    >>> leaf = assemble(build_octree(Box.parse([1, 2, 4]), 3, [parse_shape("point:0.1,0.1,0.1")]))
    >>> whole = global_delaunay(leaf)
    >>> [check_delaunay(m)["delaunay_violations"] for m in (leaf, whole)], whole.cells.regions
    ([5, 0], 1)
    """
    if found is None:
        found = check_delaunay(mesh)
    elements = found["_not_cells"]
    if not len(elements):
        return mesh
    if mesh.cells is not None:
        raise ValueError("the mesh already holds re-tessellated cells")
    bad = np.zeros(len(mesh.tree), dtype=bool)
    bad[mesh.element_leaf[elements]] = True
    types = dict(mesh.types)
    return with_cells(mesh, bad, retessellate(mesh, bad, types), types)


def retessellate(mesh: Mesh, bad: np.ndarray, types: dict) -> Cells:
    """The cells of the Delaunay subdivision of ``mesh``'s vertices inside the marked leaves (see the module's proof).

    ``mesh`` may hold only some of a tree's leaves (with the whole tree's vertices):
    a point outside its leaves is outside every region, as it is outside the marked
    leaves of the whole tree.  ``types`` receives the cells' types it lacks (id -> name, class, VTK cell).
    """
    region_of_leaf, regions = _regions(mesh, bad)
    weights = _weights(mesh)
    located = _Locator(mesh)
    tets, region_sizes = [], []
    for r in range(regions):
        leaves = np.flatnonzero(region_of_leaf == r)
        ids = np.unique(mesh.slots[leaves])
        ids = ids[ids >= 0]
        region_sizes.append(len(ids))
        tets.append(_region_tetrahedra(mesh, ids, r, region_of_leaf, located, weights))
    cells = _cells(mesh, np.concatenate(tets), weights, located, types)
    return Cells(cells.shapes, cells.shape, cells.anchor, cells.nodes, cells.leaf, cells.spanning,
                 regions=int(regions), largest_region=int(max(region_sizes)))


def with_cells(mesh: Mesh, bad: np.ndarray, cells: Cells, types: dict) -> Mesh:
    """``mesh`` with the elements of the marked leaves replaced by ``cells`` (whose ``leaf`` indexes its leaves);
    ``types``: the element types of the result."""
    counts = np.array([len(p.elements) for p in mesh.patterns], dtype=np.int64)[mesh.leaf_pattern]
    counts[bad] = 0
    offsets = np.zeros(len(mesh.tree) + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    element_leaf = np.repeat(np.arange(len(mesh.tree), dtype=np.int32), counts)
    element_local = (np.arange(offsets[-1], dtype=np.int64) - offsets[:-1][element_leaf]).astype(np.int16)
    return Mesh(mesh.tree, mesh.grid, mesh.vertices, mesh.slots, mesh.leaf_pattern, mesh.patterns, offsets,
                np.r_[element_leaf, cells.leaf.astype(np.int32)], np.r_[element_local, np.full(len(cells), -1,
                                                                                              dtype=np.int16)],
                types, replaced=bad, cells=cells)


def _regions(mesh: Mesh, bad: np.ndarray) -> tuple[np.ndarray, int]:
    """Connected parts of the marked leaves (through shared vertices): per leaf its part (-1 unmarked), and how many."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    leaves = np.flatnonzero(bad)
    slots = mesh.slots[leaves]
    row = np.repeat(np.arange(len(leaves)), slots.shape[1])
    column = slots.reshape(-1)
    keep = column >= 0
    n = len(leaves)
    graph = coo_matrix((np.ones(int(keep.sum()), dtype=np.int8), (row[keep], n + column[keep])),
                       shape=(n + len(mesh.vertices),) * 2)
    _, label = connected_components(graph, directed=False)
    part = label[:n]
    _, part = np.unique(part, return_inverse=True)
    region = np.full(len(mesh.tree), -1, dtype=np.int64)
    region[leaves] = part
    return region, int(part.max()) + 1


class _Locator:
    """Which leaf's closed box holds a grid point (4x grid units: centroids of four vertices), exactly."""

    def __init__(self, mesh: Mesh) -> None:
        tree = mesh.tree
        self.levels = np.unique(tree.levels)
        self.depth = int(tree.depth)
        self.grid = mesh.grid
        self.keys = {}
        for level in self.levels.tolist():
            leaves = np.flatnonzero(tree.levels == level)
            n = np.int64(1) << level
            p = tree.positions[leaves].astype(np.int64)
            key = (p[:, 0] * n + p[:, 1]) * n + p[:, 2]
            order = np.argsort(key)
            self.keys[level] = (key[order], leaves[order])

    def leaf(self, quad: np.ndarray) -> np.ndarray:
        """Leaf of each point given as 4 x its grid coordinates (points in the closed domain)."""
        found = np.full(len(quad), -1, dtype=np.int64)
        for level, (keys, leaves) in self.keys.items():
            size = 4 * (self.grid >> level)
            n = np.int64(1) << level
            p = np.minimum(quad // size, n - 1)
            key = (p[:, 0] * n + p[:, 1]) * n + p[:, 2]
            at = np.minimum(np.searchsorted(keys, key), len(keys) - 1)
            hit = (keys[at] == key) & (found < 0)
            found[hit] = leaves[at[hit]]
        return found


def _object_if_large(array: np.ndarray, bound: int) -> np.ndarray:
    return array.astype(object) if bound >= 2**62 else array


def _region_tetrahedra(mesh: Mesh, ids: np.ndarray, region: int, region_of_leaf: np.ndarray,
                       located: _Locator, weights) -> np.ndarray:
    """Qhull's tetrahedra of the region's vertices (global ids) that are not flat and lie in the region."""
    from scipy.spatial import Delaunay

    coords = mesh.vertices[ids].astype(np.int64)
    real = (coords - coords.min(axis=0)) * (np.array(mesh.box.to_float()) / mesh.grid)
    try:
        triangulation = Delaunay(real, qhull_options="Qbb Qc Qz Q12 Qt")
    except Exception as error:  # Qhull refuses flat input: a region is a union of boxes, never flat
        first = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
        raise CosphericalError(f"Qhull's Delaunay of a region of {len(ids)} vertices failed: {first[:200]}; "
                               "--delaunay leaf meshes without it") from None
    if len(triangulation.coplanar):
        raise CosphericalError(f"Qhull left out {len(triangulation.coplanar)} of a region's {len(ids)} vertices; "
                               "--delaunay leaf meshes without it")
    simplices = triangulation.simplices.astype(np.int64)
    p = coords[simplices]  # (tets, 4, 3)
    d = p[:, 1:] - p[:, :1]
    extent = int(np.abs(d).max()) if len(d) else 0
    d = _object_if_large(d, 6 * extent ** 3)
    volume = np.einsum("ij,ij->i", d[:, 0], np.cross(d[:, 1], d[:, 2]))
    keep = volume != 0
    simplices, p = simplices[keep], p[keep]
    leaf = located.leaf(p.sum(axis=1))
    inside = (leaf >= 0) & (region_of_leaf[np.maximum(leaf, 0)] == region)
    return ids[simplices[inside]]


def _cells(mesh: Mesh, tets: np.ndarray, weights, located: _Locator, types: dict) -> Cells:
    """Merge tetrahedra (global vertex ids) with the same exact circumcenter into cells, and measure the cells."""
    coords = mesh.vertices.astype(np.int64)
    p = coords[tets]
    d = p[:, 1:] - p[:, :1]
    extent = int(np.abs(d).max())
    w = np.array(weights, dtype=np.int64)
    bound = 24 * max(weights) * extent ** 3 * (int(coords.max()) + extent + 1)
    d = _object_if_large(d, bound)
    w = _object_if_large(w, bound)
    lifted = (d * d * w).sum(axis=2)  # (tets, 3): |d|^2 in the weighted metric
    # The sphere through the origin and d1, d2, d3: centre c with 2 W c . d_k = lifted_k,
    # so (W c) = M^-1 lifted / 2 for M the rows d_k: Cramer's rule in integers.
    det = np.einsum("ij,ij->i", d[:, 0], np.cross(d[:, 1], d[:, 2]))
    numerators = []
    for axis in range(3):
        m = d.copy()
        m[:, :, axis] = lifted
        numerators.append(np.einsum("ij,ij->i", m[:, 0], np.cross(m[:, 1], m[:, 2])))
    # centre (grid units) = p0 + num / (2 w det), per axis: an exact rational, as a reduced pair
    key = []
    for axis in range(3):
        den = 2 * w[axis] * det
        num = p[:, 0, axis].astype(den.dtype) * den + numerators[axis]
        sign = np.where(den < 0, -1, 1)
        num, den = num * sign, den * sign
        g = np.gcd(num, den) if den.dtype != object else np.frompyfunc(math.gcd, 2, 1)(num, den)
        key += [num // g, den // g]
    key = np.stack(key, axis=1)
    if key.dtype == object:
        index: dict = {}
        cell_of_tet = np.array([index.setdefault(tuple(row), len(index)) for row in key.tolist()], dtype=np.int64)
    else:
        cell_of_tet = _row_classes(key)
    cell_of_tet = cell_of_tet.reshape(-1)
    # a cell's vertices are its tetrahedra's: unique (cell, vertex) pairs, vertices in increasing id
    pairs = np.unique(np.repeat(cell_of_tet, 4) * np.int64(len(coords)) + tets.reshape(-1))
    pairs = np.stack([pairs // len(coords), pairs % len(coords)], axis=1)
    n_cells = int(cell_of_tet.max()) + 1
    counts = np.bincount(pairs[:, 0], minlength=n_cells)
    width = int(counts.max())
    starts = np.r_[0, np.cumsum(counts)[:-1]]
    position = np.arange(len(pairs)) - starts[pairs[:, 0]]
    members = np.full((n_cells, width), -1, dtype=np.int64)
    members[pairs[:, 0], position] = pairs[:, 1]
    anchor_id = members[:, 0]  # the lowest id: the lexicographically smallest point
    anchor = coords[anchor_id]
    # shapes: the offsets from the anchor, as a row of encoded integers (sorted as the ids are)
    offsets = coords[np.maximum(members, 0)] - anchor[:, None]
    span = int(np.abs(offsets).max()) + 1
    base = 2 * span + 1
    code = ((offsets[:, :, 0] + span) * base + offsets[:, :, 1] + span) * base + offsets[:, :, 2] + span
    code[members < 0] = -1
    shape_of_cell = _row_classes(np.c_[counts, code])
    shapes, orders = [], []
    for s in range(int(shape_of_cell.max()) + 1):
        cell = int(np.flatnonzero(shape_of_cell == s)[0])
        k = int(counts[cell])
        shape, order = _shape([tuple(int(x) for x in o) for o in offsets[cell, :k]], mesh.box.squared, types)
        shapes.append(shape)
        orders.append(order)
    nodes = np.full((n_cells, width), -1, dtype=np.int32)
    for s, order in enumerate(orders):
        rows = np.flatnonzero(shape_of_cell == s)
        nodes[rows, :len(order)] = members[np.ix_(rows, order)]
    # first leaf: the one holding the centroid of the cell's first tetrahedron (an interior point)
    first_tet = np.full(n_cells, -1, dtype=np.int64)
    first_tet[cell_of_tet[::-1]] = np.arange(len(tets))[::-1]
    leaf = located.leaf(p[first_tet].sum(axis=1))
    size = mesh.leaf_size()[leaf]
    low = mesh.tree.positions[leaf].astype(np.int64) * size[:, None]
    points = coords[np.maximum(nodes, 0)]
    valid = nodes >= 0
    below = np.where(valid[:, :, None], points < low[:, None], False).any(axis=(1, 2))
    above = np.where(valid[:, :, None], points > (low + size[:, None])[:, None], False).any(axis=(1, 2))
    return Cells(shapes, shape_of_cell.astype(np.int32), anchor, nodes, leaf.astype(np.int64), below | above)


def _row_classes(rows: np.ndarray) -> np.ndarray:
    """Per row, the rank of its value among the distinct rows (lexicographic): equal rows, equal class."""
    order = np.lexsort(rows.T[::-1])
    ordered = rows[order]
    new = np.r_[True, np.any(ordered[1:] != ordered[:-1], axis=1)]
    classes = np.empty(len(rows), dtype=np.int64)
    classes[order] = np.cumsum(new) - 1
    return classes


def _shape(offsets: list[tuple[int, int, int]], squared, types: dict) -> tuple[CellShape, list[int]]:
    """Classify and measure one cell shape (vertex offsets from the anchor, grid units), exactly.

    Returns the shape and the order of ``offsets`` that is the type's reference order.
    """
    points = {i: tuple(Fraction(x) for x in o) for i, o in enumerate(offsets)}
    elements = tessellation_elements(points, squared)
    if len(elements) != 1 or len(elements[0].nodes) != len(offsets):
        raise ValueError(f"merged tetrahedra are not one co-spherical cell: {offsets}")
    element = elements[0]
    types.setdefault(element.type.id, _type_info(element.type.id, element.type))
    order = list(element.nodes)
    at = {n: i for i, n in enumerate(order)}
    frame = Frame.build({i: points[n] for i, n in enumerate(order)}, squared)
    sphere = next(s for s in (frame.sphere(0, j, k, m) for j in range(1, len(order)) for k in range(j + 1, len(order))
                              for m in range(k + 1, len(order))) if s is not None)
    centre = frame.center(sphere)
    return CellShape(element.type.id, tuple(offsets[n] for n in order),
                     tuple(tuple(at[n] for n in cycle) for cycle in element.polyhedron.faces),
                     element.polyhedron.unit_volume, sphere, centre), order


MODES = ("global", "leaf")


def delaunay_mesh(mesh: Mesh, mode: str = "global", progress=None) -> tuple[Mesh, dict | None, dict | None]:
    """The mesh a user asked for: ``leaf`` (the leaf mesh as assembled) or ``global`` (its exact Delaunay subdivision).

    Returns the mesh; in ``global`` mode what the exact check found on the leaf mesh
    (``elements``, ``delaunay_violations``, ``delaunay_ties``, ``elements_replaced``),
    else ``None``; and the check itself when it also holds for the mesh returned
    (nothing was replaced: a cube octree), so that it need not run twice, else ``None``.
    ``progress(n)`` is told as the check goes through the leaf mesh's elements.
    """
    if mode not in MODES:
        raise InputError(f"--delaunay {mode!r}: write global or leaf")
    if mode == "leaf":
        return mesh, None, None
    found = check_delaunay(mesh, progress=progress)
    leaf = {"elements": len(mesh), "delaunay_violations": found["delaunay_violations"],
            "delaunay_ties": found["delaunay_ties"], "elements_replaced": int(len(found["_not_cells"]))}
    result = global_delaunay(mesh, found)
    return result, leaf, (found if result is mesh else None)
