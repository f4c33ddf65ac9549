"""The exact Delaunay subdivision of a mesh's vertex set, from the leaf mesh and a few re-tessellated clusters.

Let V be the vertices and D their Delaunay subdivision: each cell the convex hull
of all points of V on one empty sphere, the cells tiling the domain (the convex
hull of V).  The leaf mesh already tiles the domain with elements that are
co-spherical polytopes.

Why the leaf elements that pass the exact global check are kept, and the rest
re-tessellated cluster by cluster.  What the leaf mesh brings: the tree is
1-irregular (edge or vertex balance; face balance alone is refused and a leaf
list is checked for it), so two leaves whose closed boxes share a piece of a face
or of an edge differ by at most one level, and a leaf whose box meets another's
in one point only meets it at a corner of both (the boxes lie on one dyadic
grid).  Hence every vertex of V on a leaf's closed box (a corner of a leaf that
touches it) is a corner, edge midpoint or face centre of that leaf: one of its
points (:mod:`cospherical.mesh.assembly`).  Two leaves therefore hold the same
points on what they share, and each leaf's elements tile its box; the report's
``check_volume`` and ``check_conformity`` verify, exactly, that the elements tile
the domain face to face (two closed elements that meet, meet in a common face).

1. An element whose sphere holds no vertex strictly inside and no vertex of V on
   it but its own nodes is a cell of D (that is the definition of a cell).
   :func:`~cospherical.mesh.checks.check_delaunay` decides both exactly; every
   other element violates or ties.
2. Let U be the union of the closed elements of the second kind.  The kept
   elements are cells of D, and the cells of D have pairwise disjoint interiors,
   as the elements do; both tile the domain, so the cells of D that are not kept
   cover exactly what the kept elements leave: U is tiled by cells of D.
3. Split U into its connected parts U_r, elements joined when they share a
   vertex.  Two closed elements that meet share a vertex (their common face has
   one), so distinct U_r are disjoint closed sets, and a cell of D in U, being
   convex hence connected, lies in exactly one U_r.  Let V_r be the vertices of
   the elements of U_r.  A vertex v of a cell C of D inside U_r lies in a closed
   element E of U_r.  v is a node of E: v is a corner of some leaf, an extreme
   point of its box, so a vertex of the element E' of that leaf that holds it;
   E and E' meet in a common face that holds v, and a vertex of E' lying in a
   face of E' is a vertex of that face, so of E.  So v is in V_r, and C is a
   cell of Del(V_r): its vertices are in V_r, its sphere holds no point of V
   strictly inside, so none of V_r, and every point of V_r on it is in V, hence
   a vertex of C.
4. The cells of D inside U_r tile U_r (2 and 3) and are cells of Del(V_r); two
   cells of one Delaunay subdivision meet only in a common face, on both their
   boundaries, so every other cell of Del(V_r) has its interior outside U_r.
   A cell of Del(V_r) is therefore one of D's inside U_r exactly when one interior
   point x lies in U_r: the centroid of any of its tetrahedra.  Any leaf whose
   closed box holds x decides it: x lies in a closed element F of that leaf, and x
   is in U_r exactly when such an F is an element of U_r (a kept element, or one
   of another part, would overlap the interior of the cell of D that x is inside).
So D = the kept leaf elements plus, per cluster, the cells of Del(V_r) inside U_r:
every cell of D is a kept element (1) or lies in U (2), then in exactly one U_r
(3), where it is one of the cells chosen (4).  These cells tile each U_r, and
they meet the kept elements and one another face to face because all of them are
cells of one Delaunay subdivision, D.
The leaves that hold an element of U give up all their elements: the kept ones
among them are listed as cells, as they are, marked proven.

The engine (chosen by measurement: scipy's Qhull proposes, integers decide;
:mod:`cospherical.mesh.proposal`, and :mod:`cospherical.mesh.merged_cells` makes the cells):
Qhull's tetrahedra of V_r in floats; every tetrahedron is then measured in
integers on the vertex grid (weights: the squared box lengths), so only the
proposal is inexact.  Flat tetrahedra (exactly zero volume) are dropped; a
tetrahedron is inside U_r when its centroid lies in a closed element of U_r of the
leaf that holds it (integer point location, then integer plane sides); tetrahedra
with the same exact circumcenter are one cell (concentric empty spheres through
points cannot differ, so the centre names the sphere).  Qhull is given only the
vertices of U_r's elements, not those of whole leaves: measured on the 1 x 2 x 4
sphere tree of 345,640 leaves, 110,695 points in 1,305 clusters (largest 10,070)
instead of 209,793 in 239 (largest 80,067), and Qhull's time 4.2 s instead of 15.7 s.  Measured against CGAL's exact-predicate triangulation (pip ``cgal``) on
50,000 points at load 11: Qhull 13.1 s in all, CGAL 2.9 s to insert but 13.4 s to
read its cells back through the Python bindings, one object per cell; Qhull hands
back arrays.  A cell's vertices are its tetrahedra's.  Where Qhull fails (boxes of extreme aspect
ratio, 1e-12 x 1 x 3e9, whose first simplex is flat in floats) or drops a point, the
exact engine (:mod:`cospherical.core.incremental_delaunay`, Bowyer-Watson in Python
integers, about 3.6 times Qhull's path's CPU) tetrahedralises V_r instead.  Qhull's
tetrahedra are first checked per cluster in integers: across every face between two
solid tetrahedra the far vertex is not strictly inside the near one's sphere (float
rounding on thin boxes makes exactly such flips).  That check is cheap and saves a
second pass, but it proves nothing alone: it does not see the faces next to flat or
missing tetrahedra, nor overlaps.  What proves the cells, whatever proposed them:

5. The cells made for a cluster r are accepted when (i) none of them holds a vertex
   of V strictly inside its sphere or a vertex of V on it that is not its own
   (:func:`~cospherical.mesh.checks.check_delaunay` on the mesh with the cells,
   exact), and (ii) the exact volumes of the cells named by r (by the cluster of
   their first vertex: the V_r are disjoint) sum to the exact volume of U_r's
   elements.  Then they are the cells of D inside U_r.  By (i) each is a cell of D.
   Each has an interior point in U_r of its own cluster: the centroid of one of its
   solid tetrahedra (a tetrahedron on the cell's vertices lies in the cell, its
   interior in the cell's interior), kept only when it lies in a closed element of
   its tetrahedron's cluster; a point interior to a cell of D lies in no other
   closed cell, so by 2 and 4 the cell is one of those tiling U_r (a cell made of
   tetrahedra of two clusters would be one of both tilings: it fails (i)).  Two
   cells made are never the same cell of D: tetrahedra are grouped by exact
   centre, and one centre names one empty sphere.  So the cells named by r are
   distinct cells of the tiling of U_r, and their volumes sum to U_r's only if
   they are all of them.
6. Flat tetrahedra (Qhull's triangulation of co-spherical sets emits them: four
   co-circular points) have no volume and no interior point, so they are dropped
   before 5 and take no part in it: a cell is the convex hull of its vertices, and
   if its solid tetrahedra missed one of its vertices that vertex would tie with
   the cell (i); if they missed a whole cell the volume would fall short (ii).
   Tetrahedra of one centre that are not one co-spherical cell (different radii)
   cannot be classified: then every cluster is taken as failing.
7. A failing cluster is tetrahedralised again by the exact engine and the whole is
   checked again.  The exact engine's tetrahedra tile conv(V_r) and are Delaunay,
   so its cells pass; should they not, that is a bug, and it raises rather than
   return a mesh that is not D.  The check of 5 is the one the report runs on the
   mesh anyway, handed on to it (the report tests only the cells not proven):
   proving costs the volume sums, no second empty-sphere pass.
Cube octrees, whose leaf mesh is already
globally Delaunay, have no cluster: the mesh is returned as it is.

A domain that is not convex (a device's region: a union of boxes with a notch, a step
or a hole) is handled by the same steps, with V the vertices on the closed domain and
D their Delaunay subdivision, which tiles the convex hull of V and may have cells that
leave the domain.  Step 1 holds as it is (a cell's definition does not involve the
domain).  Steps 2-4 hold for a cluster U_r exactly when every cell of D that meets the
interior of U_r lies in the domain: such a cell has its interior disjoint from the kept
elements (cells of D), hence lies in U (the union of the closed clusters, which are
disjoint) and, being connected, in U_r; so U_r is tiled by cells of D and the rest of
the proof follows word for word.  Otherwise no set of cells of D tiles U_r: the cells
made pass the checks of 5 only if their volumes happen to sum to U_r's with one of them
outside the domain, an element that the caller's exact conformity check then finds
(:func:`~cospherical.mesh.regions.device_mesh` falls back to the leaf mesh); else they fail:

8. With ``convex=False``, a cluster whose exact engine's cells still fail the checks of 5
   keeps its leaf elements (each leaf's own exact Delaunay subdivision), listed as
   cells as they are, not proven: it is a cluster where a cell of D leaves the domain.
   The clusters are disjoint closed sets, so its leaf elements meet only kept leaf
   elements, face to face as in the leaf mesh.  Every element is then a cell of D or
   an element of such a cluster, and :func:`~cospherical.mesh.checks.check_delaunay`
   finds the latter whose sphere holds a vertex strictly inside as violations.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from fractions import Fraction

import numpy as np

from ..choices import ENGINES, MODES, DelaunayMode, Engine
from ..errors import InputError
from .assembly import Cells, Mesh, MeshType, distinct
from .checks import DelaunayCheck, check_delaunay, grid_weights
from .merged_cells import Locator, NotOneCell, cell_members, classified_cells, inside_cluster, same_sphere
from .proposal import Proposal, cluster_tetrahedra
from .report_sections import LeafMeshSummary

__all__ = ["delaunay_mesh", "global_delaunay", "retessellate", "with_cells"]

_NO_CLUSTER = -1  # the cluster of a leaf element that is kept, and of a vertex of no cluster


def global_delaunay(mesh: Mesh, found: DelaunayCheck | None = None, engine: Engine = "qhull",
                    proposal: Proposal | None = None,
                    convex: bool = True) -> Mesh:
    """The exact Delaunay subdivision of ``mesh``'s vertices, as a :class:`Mesh` (see the module's proof).

    ``found``: the result of :func:`check_delaunay` on ``mesh`` when the caller has it.
    ``engine``: how clusters are tetrahedralised, ``qhull`` (floats propose, integers
    check, the exact engine where either fails) or ``exact`` (the exact engine alone).
    ``proposal``: what proposes a cluster's tetrahedra in place of Qhull (see :func:`retessellate`).
    ``convex``: whether the mesh's leaves tile a convex domain; ``False``: a cluster where
    a Delaunay cell leaves the domain keeps its leaf elements (the module's step 8).

    Examples
    --------
    >>> from cospherical.core.configuration import Box
    >>> from cospherical.mesh.assembly import assemble
    >>> from cospherical.mesh.octree import build_octree, parse_shape
    >>> leaf = assemble(build_octree(Box.parse([1, 2, 4]), 3, [parse_shape("point:0.1,0.1,0.1")]))
    >>> whole = global_delaunay(leaf)
    >>> [check_delaunay(m).violations for m in (leaf, whole)], whole.cells.clusters
    ([5, 0], 1)
    """
    return _global_delaunay(mesh, found, engine, proposal, convex)[0]


def _global_delaunay(mesh: Mesh, found: DelaunayCheck | None = None, engine: Engine = "qhull",
                     proposal: Proposal | None = None, convex: bool = True) -> tuple[Mesh, DelaunayCheck | None]:
    """:func:`global_delaunay`, and :func:`check_delaunay` on the result when it ran (a cluster was re-tessellated)."""
    if engine not in ENGINES:
        raise InputError(f"engine {engine!r}: one of {', '.join(ENGINES)}")
    if found is None:
        found = check_delaunay(mesh)
    elements = found.not_cells
    if not len(elements):
        return mesh, None
    if mesh.cells is not None:
        raise InputError("global_delaunay: the mesh already holds re-tessellated cells")
    types = dict(mesh.types)
    cells, checked = retessellate(mesh, elements, types, engine, proposal, convex)
    return with_cells(mesh, _leaves_of(mesh, elements), cells, types), checked


def _leaves_of(mesh: Mesh, elements: np.ndarray) -> np.ndarray:
    """Per leaf of the mesh: whether it holds one of ``elements`` (the leaves that give up their elements)."""
    bad = np.zeros(len(mesh.tree), dtype=bool)
    bad[mesh.element_leaf[elements]] = True
    return bad


def retessellate(mesh: Mesh, elements: np.ndarray, types: dict[str, MeshType], engine: Engine = "qhull",
                 proposal: Proposal | None = None, convex: bool = True) -> tuple[Cells, DelaunayCheck]:
    """The cells of the Delaunay subdivision of ``mesh``'s vertices that replace the leaves holding ``elements``.

    ``elements``: the leaf elements that are not cells of it (see the module's proof).
    The other elements of their leaves come back as cells, as they are, marked proven.
    ``mesh`` may hold only some of a tree's leaves (with the whole tree's vertices):
    a point outside its leaves is outside every cluster, as it is outside the failing
    elements of the whole tree.  ``types`` receives the cells' types it lacks (id -> name, class, VTK cell).
    ``engine``: as for :func:`global_delaunay`.  ``proposal(real_points)``: what
    proposes a cluster's tetrahedra in place of Qhull (rows of point indices; a seam
    for tests).  The cells are proven before they are returned (the module's last
    part): a cluster whose cells fail is tetrahedralised again by the exact engine.
    ``convex=False``: a cluster whose exact engine's cells fail keeps its leaf elements
    (the module's step 8) instead of raising.
    Returns the cells and :func:`check_delaunay` on the mesh with the cells (which proved them).
    """
    nodes = mesh.element_nodes(elements)
    part, clusters = _clusters(nodes, len(mesh.vertices))
    cluster = np.full(len(mesh), _NO_CLUSTER, dtype=np.int64)
    cluster[elements] = part
    # each cluster's vertices: unique (cluster, vertex) pairs, in cluster order
    valid = nodes >= 0
    pairs = distinct(np.repeat(part, nodes.shape[1])[valid.reshape(-1)] * np.int64(len(mesh.vertices))
                      + nodes[valid])
    bounds = np.searchsorted(pairs // len(mesh.vertices), np.arange(clusters + 1))
    vertices = pairs % len(mesh.vertices)
    # the clusters' vertex sets are disjoint (a shared vertex would join them): a vertex names its cluster
    vertex_cluster = np.full(len(mesh.vertices), _NO_CLUSTER, dtype=np.int64)
    vertex_cluster[vertices] = pairs // len(mesh.vertices)
    located = Locator(mesh)
    # the other elements of the leaves that give up theirs: cells as they are, proven by the check
    leaves = distinct(mesh.element_leaf[elements])
    counts = mesh.element_offsets[leaves + 1] - mesh.element_offsets[leaves]
    given_up = np.repeat(mesh.element_offsets[leaves] - np.r_[0, np.cumsum(counts)[:-1]], counts) \
        + np.arange(int(counts.sum()))
    proven = mesh.element_nodes(given_up[cluster[given_up] == _NO_CLUSTER])
    bad = _leaves_of(mesh, elements)
    wanted = _cluster_volumes(mesh, elements, part, clusters)
    tets = [cluster_tetrahedra(mesh, vertices[bounds[r]:bounds[r + 1]], engine, proposal) for r in range(clusters)]
    exact = set(range(clusters)) if engine == "exact" else set()
    fallen: set[int] = set()  # clusters that keep their leaf elements (step 8)
    while True:
        tet_cluster = np.concatenate([np.full(len(t), r, dtype=np.int64) for r, t in enumerate(tets)])
        every = np.concatenate(tets)
        every = every[inside_cluster(mesh, every, tet_cluster, cluster, located)]
        try:
            merged = cell_members(same_sphere(mesh, every, grid_weights(mesh)), every, len(mesh.vertices)) \
                if len(every) else np.zeros((0, 1), dtype=np.int64)
            if fallen:
                merged = _stacked(merged, mesh.element_nodes(elements[np.isin(part, sorted(fallen))]))
            cells = classified_cells(mesh, merged, proven, located, types)
        except NotOneCell:  # no cell to name a cluster by: no proof per cluster
            failing = set(range(clusters)) - fallen
        else:
            cells = Cells(cells.shapes, cells.shape, cells.anchor, cells.nodes, cells.leaf, cells.spanning,
                          cells.proven, clusters=int(clusters), largest_cluster=int(np.diff(bounds).max()))
            trial = with_cells(mesh, bad, cells, types)
            found = check_delaunay(trial)
            failing = _failing_clusters(trial, found, vertex_cluster, wanted) - fallen
            if not failing:
                return cells, found
        if failing & exact and convex:  # the exact engine's cells are Delaunay by construction: a bug, not rounding
            raise RuntimeError(f"the exact engine's cells of clusters {sorted(failing & exact)[:5]} fail the "
                               "exact checks")
        for r in failing & exact:  # a Delaunay cell leaves the (non-convex) domain here: the leaf elements stay
            tets[r] = tets[r][:0]
        fallen |= failing & exact
        for r in failing - exact:
            tets[r] = cluster_tetrahedra(mesh, vertices[bounds[r]:bounds[r + 1]], "exact")
        exact |= failing


def _stacked(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """Two tables of vertex ids (-1 padded) as one, padded to the wider."""
    width = max(first.shape[1], second.shape[1])
    return np.concatenate([np.pad(t, ((0, 0), (0, width - t.shape[1])), constant_values=-1)
                           for t in (first, second)])


def _cluster_volumes(mesh: Mesh, elements: np.ndarray, part: np.ndarray, clusters: int) -> list[Fraction]:
    """Per cluster, the exact volume of its elements in grid cells."""
    leaf = mesh.element_leaf[elements]
    kind = mesh.leaf_tessellation[leaf].astype(np.int64) * 65536 + mesh.element_local[elements]
    size = (mesh.grid >> mesh.tree.levels[leaf].astype(np.int64)).astype(object) ** 3
    volumes = [Fraction(0)] * clusters
    # elements of one local element (tessellation, element in it) and one cluster: one Fraction product per pair
    for (r, k), total in _sums(part * (int(kind.max()) + 1) + kind, size, int(kind.max()) + 1):
        element = mesh.tessellations[k // 65536].elements[k % 65536]
        volumes[r] += element.unit_volume * total
    return volumes


def _sums(key: np.ndarray, values: np.ndarray, base: int) -> Iterator[tuple[tuple[int, int], int]]:
    """Per distinct key, ((key // base, key % base), the sum of its values (Python integers))."""
    order = np.argsort(key, kind="stable")
    key, values = key[order], values[order]
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    for start, total in zip(starts.tolist(), np.add.reduceat(values, starts).tolist() if len(starts) else []):
        yield divmod(int(key[start]), base), total


def _failing_clusters(mesh: Mesh, found: DelaunayCheck, vertex_cluster: np.ndarray,
                      wanted: list[Fraction]) -> set[int]:
    """The clusters whose re-tessellated cells are not proven cells of the Delaunay subdivision (the module's proof).

    A cluster fails when one of its cells is not empty or ties with a vertex, or when
    its cells' exact volumes do not sum to its elements'.
    """
    cells = mesh.cells
    if cells is None:
        raise RuntimeError("a trial mesh without its cells")
    fresh = np.flatnonzero(~cells.proven)
    # A fresh cell's vertices are its tetrahedra's, all of one cluster (the clusters' vertex sets are
    # disjoint): its first vertex names the cluster.  The proven cells belong to no cluster.
    cell_cluster = np.full(len(cells), _NO_CLUSTER, dtype=np.int64)
    cell_cluster[fresh] = vertex_cluster[cells.nodes[fresh, 0]]
    # check_delaunay tests only the fresh cells (the kept leaf elements and the proven cells passed it on
    # the same vertex set), so every element it finds is a fresh cell: anything else is a bug, not a cluster.
    not_cells = found.not_cells - mesh.leaf_elements  # indices among the cells
    if np.any(cell_cluster[fresh] == _NO_CLUSTER) or np.any(not_cells < 0) \
            or np.any(cell_cluster[not_cells] == _NO_CLUSTER):
        raise RuntimeError("an element that is not a fresh cell of a cluster was found not to be a cell")
    failing = set(cell_cluster[not_cells].tolist())
    volumes = [Fraction(0)] * len(wanted)
    key = cell_cluster[fresh] * len(cells.shapes) + cells.shape[fresh]
    for (r, s), n in _sums(key, np.ones(len(fresh), dtype=object), len(cells.shapes)):
        volumes[r] += cells.shapes[s].grid_volume * n
    return failing | {r for r, (v, w) in enumerate(zip(volumes, wanted)) if v != w}


def with_cells(mesh: Mesh, bad: np.ndarray, cells: Cells, types: dict[str, MeshType]) -> Mesh:
    """``mesh`` with the elements of the marked leaves replaced by ``cells`` (whose ``leaf`` indexes its leaves);
    ``types``: the element types of the result."""
    counts = np.array([len(p.elements) for p in mesh.tessellations], dtype=np.int64)[mesh.leaf_tessellation]
    counts[bad] = 0
    offsets = np.zeros(len(mesh.tree) + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    element_leaf = np.repeat(np.arange(len(mesh.tree), dtype=np.int32), counts)
    element_local = (np.arange(offsets[-1], dtype=np.int64) - offsets[:-1][element_leaf]).astype(np.int16)
    return Mesh(mesh.tree, mesh.grid, mesh.vertices, mesh.slots, mesh.leaf_tessellation, mesh.tessellations, offsets,
                np.r_[element_leaf, cells.leaf.astype(np.int32)], np.r_[element_local, np.full(len(cells), -1,
                                                                                              dtype=np.int16)],
                types, replaced=bad, cells=cells, catalogue=mesh.catalogue, regions=mesh.regions)


def _clusters(nodes: np.ndarray, vertices: int) -> tuple[np.ndarray, int]:
    """Connected parts of elements (rows of vertex ids, -1 padded) through shared vertices: per row its part, and how many."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = len(nodes)
    row = np.repeat(np.arange(n), nodes.shape[1])
    column = nodes.reshape(-1)
    keep = column >= 0
    graph = coo_matrix((np.ones(int(keep.sum()), dtype=np.int8), (row[keep], n + column[keep])),
                       shape=(n + vertices,) * 2)
    _, label = connected_components(graph, directed=False)
    used = np.zeros(int(label.max()) + 1, dtype=bool)
    used[label[:n]] = True
    part = (np.cumsum(used) - 1)[label[:n]]  # the labels the rows use, numbered in order
    return part, int(part.max()) + 1


def delaunay_mesh(mesh: Mesh, mode: DelaunayMode = "global", progress: Callable[[int], None] | None = None,
                  convex: bool = True
                  ) -> tuple[Mesh, LeafMeshSummary | None, DelaunayCheck | None]:
    """The mesh a user asked for: ``leaf`` (the leaf mesh as assembled) or ``global`` (its exact Delaunay subdivision).

    Returns the mesh; in ``global`` mode what the exact check found on the leaf mesh
    (``elements``, ``delaunay_violations``, ``delaunay_ties``, ``elements_replaced``),
    else ``None``; and :func:`check_delaunay` on the mesh returned in ``global`` mode
    (on the leaf mesh when nothing was replaced: a cube octree; else the one that
    proved the cells), so that it need not run twice, else ``None``.
    ``progress(n)`` is told as the check goes through the leaf mesh's elements.
    ``convex``: whether the leaves tile a convex domain (see :func:`global_delaunay`).
    """
    if mode not in MODES:
        raise InputError(f"--delaunay {mode!r}: write global or leaf")
    if mode == "leaf":
        return mesh, None, None
    found = check_delaunay(mesh, progress=progress)
    leaf = found.leaf_mesh(len(mesh))
    result, checked = _global_delaunay(mesh, found, convex=convex)
    return result, leaf, (found if result is mesh else checked)
