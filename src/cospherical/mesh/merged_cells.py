"""Tetrahedra merged into cells: grouped by exact circumcentre, kept where they lie in their cluster, classified.

What :func:`~cospherical.mesh.delaunay.retessellate` does with the tetrahedra proposed
for its clusters (:mod:`cospherical.mesh.proposal`), all in integers on the vertex grid:
which leaf's closed box holds a point (:class:`Locator`), whether a tetrahedron's
centroid lies in a closed element of its own cluster (:func:`inside_cluster`), which
tetrahedra share one exact circumcentre (:func:`same_sphere`: one centre names one empty
sphere, so one cell), and each cell's vertices, element type, reference order, volume
and sphere (:func:`classified_cells`), measured once per shape up to translation and scale.
"""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction

import numpy as np

from ..catalogue import Catalogue
from ..core.geometry import Frame, area_vector, circumcenters
from ..core.tessellation import tessellation_elements
from .assembly import NODE_OFFSETS, CellShape, Cells, Mesh, MeshType, distinct, type_info

__all__ = ["Locator", "NotOneCell", "cell_members", "cell_shape", "classified_cells", "element_planes",
           "inside_cluster", "row_classes", "same_sphere", "scaled_shape"]


class NotOneCell(Exception):
    """Tetrahedra of one exact centre whose vertices are not one co-spherical cell (different radii).

    Only a wrong proposal makes them; :func:`~cospherical.mesh.delaunay.retessellate` then redoes every cluster with
    the exact engine.  Its own class, so that no other error is taken for this one.
    """


class Locator:
    """Which leaf's closed box holds a point given as an integer multiple of its grid coordinates, exactly."""

    def __init__(self, mesh: Mesh) -> None:
        tree = mesh.tree
        self.levels = np.unique(tree.levels)
        self.grid = mesh.grid
        self.keys = {}
        for level in self.levels.tolist():
            leaves = np.flatnonzero(tree.levels == level)
            n = np.int64(1) << level
            p = tree.positions[leaves].astype(np.int64)
            key = (p[:, 0] * n + p[:, 1]) * n + p[:, 2]
            order = np.argsort(key)
            self.keys[level] = (key[order], leaves[order])

    def leaf(self, points: np.ndarray, scale: int | np.ndarray = 4) -> np.ndarray:
        """Leaf of each point given as ``scale`` (a number, or one per point) x its grid coordinates, in the closed domain."""
        found = np.full(len(points), -1, dtype=np.int64)
        scale = np.asarray(scale, dtype=np.int64).reshape(-1, 1)
        for level, (keys, leaves) in self.keys.items():
            size = scale * (self.grid >> level)
            n = np.int64(1) << level
            p = np.minimum(points // size, n - 1)
            key = (p[:, 0] * n + p[:, 1]) * n + p[:, 2]
            at = np.minimum(np.searchsorted(keys, key), len(keys) - 1)
            hit = (keys[at] == key) & (found < 0)
            found[hit] = leaves[at[hit]]
        return found


def inside_cluster(mesh: Mesh, tets: np.ndarray, tet_cluster: np.ndarray, cluster: np.ndarray, located: Locator) -> np.ndarray:
    """Per tetrahedron: its centroid lies in a closed element of its cluster, of the leaf whose box holds it (exactly).

    ``cluster``: per leaf element its cluster, ``_NO_CLUSTER`` for the kept ones.  In the leaf's own
    frame (4 x grid units from its lowest corner) node ``s`` sits at ``2 size
    NODE_OFFSETS[s]``; an element holds the point when no face plane has it on the
    side away from the element's vertex centroid.  The numbers are below 100 times
    the grid (at most 2**17): int64.
    """
    coords = mesh.vertices.astype(np.int64)
    quad = coords[tets].sum(axis=1)
    # a centroid outside the mesh's leaves (it may hold only some of a tree's) is outside every cluster
    found = located.leaf(quad)
    tets, tet_cluster, quad, leaf = tets[found >= 0], tet_cluster[found >= 0], quad[found >= 0], found[found >= 0]
    size = mesh.leaf_size()[leaf]
    local = quad - 4 * mesh.tree.positions[leaf].astype(np.int64) * size[:, None]
    first = mesh.element_offsets[leaf]
    which = mesh.leaf_tessellation[leaf]
    inside = np.zeros(len(tets), dtype=bool)
    order = np.argsort(which, kind="stable")
    starts = np.searchsorted(which[order], np.arange(len(mesh.tessellations) + 1))
    for p, each_element in enumerate(element_planes(mesh)):
        rows = order[starts[p]:starts[p + 1]]
        for j, planes in enumerate(each_element):
            rows_j = rows[cluster[first[rows] + j] == tet_cluster[rows]]
            holds = np.ones(len(rows_j), dtype=bool)
            for normal, corner, side in planes:
                holds &= side * ((local[rows_j] - 2 * size[rows_j, None] * corner) @ normal) >= 0
            inside[rows_j[holds]] = True
    result = np.zeros(len(found), dtype=bool)
    result[np.flatnonzero(found >= 0)] = inside
    return result


def element_planes(mesh: Mesh) -> list[list[list[tuple[np.ndarray, np.ndarray, int]]]]:
    """Per tessellation, per element, its face planes in the node grid: (normal, a point, sign of the inside)."""
    planes: list[list[list[tuple[np.ndarray, np.ndarray, int]]]] = []
    for tessellation in mesh.tessellations:
        planes.append([])
        for element in tessellation.elements:
            centroid = NODE_OFFSETS[list(element.nodes)].sum(axis=0)
            faces = []
            for cycle in element.faces:
                points = NODE_OFFSETS[list(cycle)]
                normal = np.array(area_vector(points.tolist()), dtype=np.int64)
                side = int(np.sign((centroid - len(element.nodes) * points[0]) @ normal))
                faces.append((normal, points[0], side))
            # a flat element (no faces, reported by the volume check) holds nothing
            planes[-1].append(faces if faces else [(np.zeros(3, dtype=np.int64), NODE_OFFSETS[0], -1)])
    return planes


def same_sphere(mesh: Mesh, tets: np.ndarray, weights: Sequence[int]) -> np.ndarray:
    """Per tetrahedron (global vertex ids), the class of its exact circumcenter: one class, one cell."""
    num, den = circumcenters(mesh.vertices.astype(np.int64)[tets], weights)
    key = np.stack((num, den), axis=2).reshape(len(tets), 6)  # per axis its numerator and denominator
    if key.dtype == object:
        index: dict[tuple[int, ...], int] = {}
        return np.array([index.setdefault(tuple(row), len(index)) for row in key.tolist()], dtype=np.int64)
    return row_classes(key).reshape(-1)


def cell_members(cell_of_tet: np.ndarray, tets: np.ndarray, vertices: int) -> np.ndarray:
    """A cell's vertices are its tetrahedra's: per cell its vertex ids, increasing, padded with -1."""
    pairs = distinct(np.repeat(cell_of_tet, 4) * np.int64(vertices) + tets.reshape(-1))
    cell, vertex = pairs // vertices, pairs % vertices
    counts = np.bincount(cell, minlength=int(cell_of_tet.max()) + 1 if len(cell_of_tet) else 0)
    members = np.full((len(counts), int(counts.max()) if len(counts) else 1), -1, dtype=np.int64)
    members[cell, np.arange(len(pairs)) - np.r_[0, np.cumsum(counts)[:-1]][cell]] = vertex
    return members


def classified_cells(mesh: Mesh, merged: np.ndarray, proven: np.ndarray, located: Locator,
                     types: dict[str, MeshType]) -> Cells:
    """The cells (rows of vertex ids, -1 padded): the merged ones and the ``proven`` kept elements, classified and measured.

    Cells are listed in the order of their sorted vertex ids, so the result does not
    depend on the order Qhull hands its tetrahedra back.
    """
    coords = mesh.vertices.astype(np.int64)
    width = max(merged.shape[1], proven.shape[1])
    rows = np.full((len(merged) + len(proven), width), -1, dtype=np.int64)
    rows[:len(merged), :merged.shape[1]] = merged
    rows[len(merged):, :proven.shape[1]] = proven
    is_proven = np.r_[np.zeros(len(merged), dtype=bool), np.ones(len(proven), dtype=bool)]
    # vertex ids increasing, the padding last; then the cells in the order of these rows
    members = np.sort(np.where(rows < 0, len(coords), rows), axis=1)
    order = np.lexsort(members.T[::-1])
    members, is_proven = members[order], is_proven[order]
    members[members == len(coords)] = -1
    valid = members >= 0
    counts = valid.sum(axis=1)
    n_cells = len(members)
    anchor_id = members[:, 0]  # the lowest id: the lexicographically smallest point
    anchor = coords[anchor_id]
    # shapes: the offsets from the anchor, as a row of encoded integers (sorted as the ids are)
    offsets = coords[np.maximum(members, 0)] - anchor[:, None]
    span = int(np.abs(offsets).max()) + 1
    base = 2 * span + 1
    code = ((offsets[:, :, 0] + span) * base + offsets[:, :, 1] + span) * base + offsets[:, :, 2] + span
    code[~valid] = -1
    shape_of_cell = row_classes(np.c_[counts, code])
    by_shape = np.argsort(shape_of_cell, kind="stable")
    starts = np.searchsorted(shape_of_cell[by_shape], np.arange(int(shape_of_cell.max()) + 2))
    shapes = []
    nodes = np.full((n_cells, width), -1, dtype=np.int32)
    assert mesh.catalogue is not None  # assemble gives every mesh its catalogue
    measured: dict[bytes, tuple[CellShape, list[int]]] = {}  # shapes up to scale (the same cells at another leaf level): classified once
    for s in range(len(starts) - 1):
        rows = by_shape[starts[s]:starts[s + 1]]
        k = int(counts[rows[0]])
        g = int(np.gcd.reduce(np.abs(offsets[rows[0], :k]).reshape(-1)))
        unit = offsets[rows[0], :k] // g
        if unit.tobytes() not in measured:
            measured[unit.tobytes()] = cell_shape([(int(o[0]), int(o[1]), int(o[2])) for o in unit],
                                                  mesh.box.squared, types, mesh.catalogue)
        shape, reference = measured[unit.tobytes()]
        shapes.append(scaled_shape(shape, g))
        nodes[rows, :len(reference)] = members[np.ix_(rows, np.array(reference, dtype=np.int64))]
    # first leaf: the one whose box holds the cell's vertex centroid (an interior point)
    points = coords[np.maximum(members, 0)]
    leaf = located.leaf(np.where(valid[:, :, None], points, 0).sum(axis=1), counts)
    size = mesh.leaf_size()[leaf]
    low = mesh.tree.positions[leaf].astype(np.int64) * size[:, None]
    below = np.where(valid[:, :, None], points < low[:, None], False).any(axis=(1, 2))
    above = np.where(valid[:, :, None], points > (low + size[:, None])[:, None], False).any(axis=(1, 2))
    return Cells(shapes, shape_of_cell.astype(np.int32), anchor, nodes, leaf.astype(np.int64),
                 np.asarray(below | above), is_proven)


def row_classes(rows: np.ndarray) -> np.ndarray:
    """Per row, the rank of its value among the distinct rows (lexicographic): equal rows, equal class."""
    order = np.lexsort(rows.T[::-1])
    ordered = rows[order]
    new = np.r_[True, np.any(ordered[1:] != ordered[:-1], axis=1)]
    classes = np.empty(len(rows), dtype=np.int64)
    classes[order] = np.cumsum(new) - 1
    return classes


def cell_shape(offsets: list[tuple[int, int, int]], squared: tuple[Fraction, Fraction, Fraction],
               types: dict[str, MeshType], catalogue: Catalogue) -> tuple[CellShape, list[int]]:
    """Classify and measure one cell shape (vertex offsets from the anchor, grid units), exactly.

    Returns the shape and the order of ``offsets`` that is the type's reference order.
    """
    points = {i: tuple(Fraction(x) for x in o) for i, o in enumerate(offsets)}
    elements = tessellation_elements(points, squared)
    if len(elements) != 1 or len(elements[0].nodes) != len(offsets):
        raise NotOneCell(f"merged tetrahedra are not one co-spherical cell: {offsets}")
    element = elements[0]
    types.setdefault(element.type.id, type_info(element.type.id, element.type, catalogue))
    order = list(element.nodes)
    at = {n: i for i, n in enumerate(order)}
    frame = Frame.build({i: points[n] for i, n in enumerate(order)}, squared)
    sphere = frame.circumsphere(range(len(order)))
    if sphere is None:
        raise NotOneCell(f"merged tetrahedra have no sphere: {offsets}")
    center = frame.center(sphere)
    return CellShape(element.type.id, tuple(offsets[n] for n in order),
                     tuple(tuple(at[n] for n in cycle) for cycle in element.polyhedron.faces),
                     element.polyhedron.unit_volume, sphere, center), order


def scaled_shape(shape: CellShape, g: int) -> CellShape:
    """``shape`` scaled by the integer ``g`` about its anchor: what :func:`cell_shape` gives for the scaled offsets.

    Lexicographic order, the type and its node order do not change, nor the four
    nodes of its sphere (:meth:`~cospherical.core.geometry.Sphere.scaled`).
    """
    if g == 1:
        return shape
    x, y, z = shape.center
    return CellShape(shape.type_id, tuple((g * a, g * b, g * c) for a, b, c in shape.offsets), shape.faces,
                     shape.grid_volume * g ** 3, shape.sphere.scaled(g), (g * x, g * y, g * z))
