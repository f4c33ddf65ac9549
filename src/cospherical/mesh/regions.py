"""A device's mesh: elements in regions, the exact Delaunay subdivision region by region, contacts and interfaces.

Each leaf of a device's tree lies in one region (:mod:`cospherical.mesh.device`), so
each leaf element does.  In the global Delaunay mode the elements of each **region**
are built from the exact Delaunay subdivision D_R of the vertices on the closed region
(the union of its boxes), as the whole-domain mode builds it
(:mod:`cospherical.mesh.delaunay`, with the region as the domain: it is tiled by its
leaves, and its vertices are the corners of its leaves).  So:

- every element lies in one region; a cell never crosses an interface or the domain's
  boundary, but may cross a face between two boxes of one region;
- a convex region gets exactly D_R: each element's circumsphere holds no vertex of the
  region strictly inside, and none on it but the element's own nodes;
- in a region that is not convex, a cluster of leaf elements where a cell of D_R
  leaves the region keeps its leaf elements (the module's step 8); every other
  element is a cell of D_R.  The check finds those of the first kind whose sphere
  holds a vertex as violations.  A vertex *outside* the region may lie inside an
  element's sphere (behind an interface, across a notch): the box method's
  coefficients of such elements can be negative, and the report counts the negative
  interior coefficients per region;
- across an interface both sides are cut by the Delaunay subdivision of the points
  on the face; the report's exact conformity check says whether they match
  (``nonconforming_faces``).  Where they do not, the mesh falls back to the leaf
  elements (each leaf's exact Delaunay subdivision, conforming by construction) and
  says so (``delaunay_mode``).

A device of one region is meshed as the region alone, one of one box exactly as a
one-box domain.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from fractions import Fraction
from collections.abc import Sequence
from typing import Any, Callable

import numpy as np

from ..choices import DelaunayMode
from ..core.configuration import Box
from ..errors import InputError

from .assembly import Cells, Lookup, Mesh, assemble, vertex_keys
from .checks import DelaunayCheck, check_conformity
from .delaunay import delaunay_mesh, with_cells
from .dual import Dual, RegionParts, mesh_dual
from .device import DeviceLayout, Regions
from .octree import Octree
from .report_sections import (ContactSummary, DeviceSummary, InterfaceSummary, LeafMeshSummary, NegativeCoefficients,
                              RegionSummary)
from .surfaces import edge_keys, vertex_parts

__all__ = ["RegionFaces", "contact_areas", "device_mesh", "device_report", "face_sets", "mesh_region_parts", "region_faces", "region_parts",
           "region_volumes"]


def device_mesh(layout: DeviceLayout, tree: Octree, leaf_region: np.ndarray, lookup: Lookup | None = None,
                criterion: str = "optimal", mode: DelaunayMode = "global",
                progress: Callable[[str, int | None, int], None] | None = None,
                cache: dict[Any, Any] | None = None) -> tuple[Mesh, LeafMeshSummary | None, DelaunayCheck | None]:
    """Mesh a device's tree: the leaf mesh, then in ``global`` mode the exact Delaunay subdivision region by region.

    Returns what :func:`~cospherical.mesh.delaunay.delaunay_mesh` returns: the mesh,
    what the check found on the leaf mesh (summed over the regions), and the check of
    the result (the regions' checks summed, each against its own region's vertices; its
    elements numbered as the mesh returned numbers them).
    ``progress(stage, total, advance)``: told of the stages as the one-box pipeline
    tells them (``assembly`` through the leaves, ``regions`` through the leaf mesh's
    elements), so a device's mesh shows the same bars.
    """
    device = layout.device
    regions = Regions(tuple(r.name for r in device.regions), tuple(r.material for r in device.regions),
                      leaf_region, layout)
    cache = {} if cache is None else cache
    mesh = assemble(tree, lookup, criterion=criterion, cache=cache,
                    progress=None if progress is None else (lambda n: progress("assembly", len(tree), n)))
    mesh.regions = regions
    count = len(device.regions)
    if mode != "global" or count == 1:  # one region: its vertices are the mesh's
        return delaunay_mesh(mesh, mode, convex=layout.convex(0),
                             progress=None if progress is None else (lambda n: progress("regions", len(mesh), n)))
    grid, keys = vertex_keys(tree)
    n = np.int64(grid + 1)
    points = np.stack([keys // (n * n), (keys // n) % n, keys % n], axis=1)
    factor = grid // layout.steps
    bounds = _box_bounds(layout) * factor
    first_box = np.cumsum([0] + [len(r.boxes) for r in device.regions])
    done: list[tuple[np.ndarray, Mesh, DelaunayCheck | None]] = []
    parts: list[Cells] = []
    found: list[LeafMeshSummary] = []
    types = dict(mesh.types)
    bad = np.zeros(len(tree), dtype=bool)
    for r in range(count):
        leaves = np.flatnonzero(leaf_region == r)
        # the vertices on the closed region: on one of its closed boxes
        on = np.zeros(len(points), dtype=bool)
        for low_high in bounds[first_box[r]:first_box[r + 1]]:
            on |= np.all((points >= low_high[:3]) & (points <= low_high[3:]), axis=1)
        ids = np.flatnonzero(on)
        sub = assemble(Octree(tree.box, tree.levels[leaves], tree.positions[leaves], tree.vertex_balanced), lookup,
                       cache=cache,
                       criterion=criterion, vertices=(grid, keys[ids]), catalogue=mesh.catalogue)
        result, figures, checked = delaunay_mesh(sub, "global", convex=layout.convex(r))
        if figures is not None:  # always, in global mode
            found.append(figures)
        done.append((leaves, result, checked))
        if result.cells is None:
            continue
        types.update(result.types)
        bad[leaves[result.replaced]] = True
        cells = result.cells
        nodes = np.where(cells.nodes >= 0, ids[np.maximum(cells.nodes, 0)], -1).astype(np.int32)
        parts.append(Cells(cells.shapes, cells.shape, cells.anchor, nodes, leaves[cells.leaf], cells.spanning,
                           cells.proven, cells.clusters, cells.largest_cluster))
    leaf = sum(found[1:], found[0])
    result = with_cells(mesh, bad, _merged(parts), types) if parts else mesh
    if parts and check_conformity(result, examples=0).nonconforming_faces:
        # the regions' subdivisions do not meet face to face: the leaf mesh, conforming by construction
        return mesh, replace(leaf, fallback="leaf elements: the regions' Delaunay subdivisions do not meet face to face"), \
            None
    return result, leaf, _summed_checks(result, done)


def _summed_checks(whole: Mesh, done: list[tuple[np.ndarray, Mesh, DelaunayCheck | None]]) -> DelaunayCheck | None:
    """The regions' Delaunay checks as one, their leaves and elements numbered as in ``whole`` (the merged mesh).

    ``done``: per region its leaves (indices into the whole tree), its mesh and its check
    (``None``: not checked, then neither is the whole).  A region's leaf element keeps its
    leaf and place in it; its cells follow the earlier regions' cells.
    """
    if any(checked is None for _, _, checked in done):
        return None
    counts = {name: sum(getattr(c, name) for _, _, c in done if c is not None)
              for name in ("violations", "violating_pairs", "violating_leaves", "ties", "exact_tests", "bounded",
                           "searched")}
    leaf_ids, elements, not_cells = [], [], []
    first_cell = whole.leaf_elements
    for leaves, sub, checked in done:
        assert checked is not None

        def numbered(local: np.ndarray, sub: Mesh = sub, leaves: np.ndarray = leaves,
                     first_cell: int = first_cell) -> np.ndarray:
            is_cell = local >= sub.leaf_elements
            leaf = leaves[sub.element_leaf[local]]
            return np.where(is_cell, first_cell + local - sub.leaf_elements,
                            whole.element_offsets[leaf] + sub.element_local[local])

        leaf_ids.append(leaves[checked.violating_leaf_ids])
        elements.append(numbered(checked.violating_elements))
        not_cells.append(numbered(checked.not_cells))
        first_cell += len(sub.cells) if sub.cells is not None else 0
    leaf_ids_found, elements_found, not_cells_found = (np.sort(np.concatenate(a)).astype(np.int64)
                                                       for a in (leaf_ids, elements, not_cells))
    return DelaunayCheck(counts["violations"], counts["violating_pairs"], counts["violating_leaves"], counts["ties"],
                         counts["exact_tests"], leaf_ids_found, elements_found, not_cells_found, counts["bounded"],
                         counts["searched"])


def _box_bounds(layout: DeviceLayout) -> np.ndarray:
    """Every box of the device (file order over the regions) in steps of the resolving level, (boxes x 6)."""
    device = layout.device
    bounds = device.bounds
    rows = []
    for region in device.regions:
        for box in region.boxes:
            rows.append([int((box[i] - bounds[i % 3][0]) / (bounds[i % 3][1] - bounds[i % 3][0]) * layout.steps)
                         for i in range(6)])
    return np.array(rows, dtype=np.int64).reshape(-1, 6)


def _merged(parts: list[Cells]) -> Cells:
    """The cells of several regions as one :class:`Cells` (shape indices shifted past the earlier regions' shapes)."""
    shapes, shape, offset = [], [], 0
    for cells in parts:
        shapes.extend(cells.shapes)
        shape.append(cells.shape + offset)
        offset += len(cells.shapes)
    width = max(c.nodes.shape[1] for c in parts)
    nodes = np.concatenate([np.pad(c.nodes, ((0, 0), (0, width - c.nodes.shape[1])), constant_values=-1)
                            for c in parts])
    return Cells(shapes, np.concatenate(shape).astype(np.int32), np.concatenate([c.anchor for c in parts]), nodes,
                 np.concatenate([c.leaf for c in parts]), np.concatenate([c.spanning for c in parts]),
                 np.concatenate([c.proven for c in parts]), sum(c.clusters for c in parts),
                 max(c.largest_cluster for c in parts))


def device_of(mesh: Mesh) -> tuple[Regions, DeviceLayout, np.ndarray]:
    """A device mesh's regions, layout and each element's region; a mesh of no device is refused."""
    regions = mesh.regions
    if regions is None or regions.layout is None:
        raise InputError("not a device's mesh: it has no regions")
    return regions, regions.layout, regions.leaf_region[mesh.element_leaf]


@dataclass(frozen=True)
class RegionFaces:
    """A device mesh's named face sets: contacts and interfaces (polygons of global vertex ids, -1 padded).

    Contact faces: ``contact_nodes`` (f x w), counter-clockwise seen from outside their
    element ``contact_element``, on contact ``contact_face_contact`` (index into the
    device's contacts).  Interface faces, once each: ``interface_nodes``, oriented out
    of ``interface_element[:, 0]`` (the element of the lower region index) into
    ``interface_element[:, 1]``; ``interface_face_interface`` indexes ``interfaces``,
    the pairs of touching regions ``(a, b)``, ``a < b``, named ``"name_a|name_b"``.
    ``boundary_nodes``: every face met by one element only (the domain's boundary, the
    contacts' faces among them), as its element has it; ``boundary_edges``: the keys
    ``i * V + j`` (``i < j``, ``V`` vertices) of those faces' edges.
    """

    contact_nodes: np.ndarray
    contact_element: np.ndarray
    contact_face_contact: np.ndarray
    interfaces: np.ndarray
    interface_names: tuple[str, ...]
    interface_nodes: np.ndarray
    interface_element: np.ndarray
    interface_face_interface: np.ndarray
    boundary_edges: np.ndarray
    boundary_nodes: np.ndarray

    def contact_vertices(self, contact: int) -> np.ndarray:
        """The distinct vertices of a contact's faces, increasing."""
        nodes = self.contact_nodes[self.contact_face_contact == contact]
        return np.unique(nodes[nodes >= 0])


def region_faces(mesh: Mesh) -> RegionFaces:
    """The contact and interface faces of a device mesh (see :class:`RegionFaces`).

    Faces flat in a block plane (the only ones that can be) are paired by their sorted
    global vertex ids; a face met once (on the domain's boundary) or an interface face, as
    the element of the contact's region has it, lies on a contact when it is flat in the
    contact's plane and its vertices lie in the contact's closed rectangle (a face of a
    conforming mesh lies in one leaf face, which lies inside or outside the contact: the
    tree was refined so).  A contact lies on the outer boundary or on an interface: its
    region is on one side only.
    """
    regions, layout, element_region = device_of(mesh)
    rows, polygons = [], []
    vertices = mesh.vertices.astype(np.int64)
    planes = [plane * (mesh.grid // layout.steps) for plane in layout.planes]
    in_plane = np.stack([np.isin(vertices[:, axis], planes[axis]) for axis in range(3)], axis=1)
    on_some_plane: np.ndarray = np.any(in_plane, axis=1)
    for element_rows, nodes, faces, _ in mesh.blocks():
        for cycle in faces:
            polygon = nodes[:, list(cycle)]
            on = _on_a_plane(vertices, polygon, in_plane, on_some_plane)
            rows.append(element_rows[on])
            polygons.append(polygon[on])
    if not rows:
        empty = np.zeros((0, 0), dtype=np.int32)
        return RegionFaces(empty, np.zeros(0, np.int64), np.zeros(0, np.int32), np.zeros((0, 2), np.int32), (),
                           empty, np.zeros((0, 2), np.int64), np.zeros(0, np.int32), np.zeros(0, np.int64), empty)
    element, face, ones, interface_element, interfaces, which = face_sets(np.concatenate(rows), polygons,
                                                                          element_region)
    names = tuple(f"{regions.names[a]}|{regions.names[b]}" for a, b in interfaces.tolist())
    # contacts: faces met once or on an interface (either side's copy: the contact's region picks one), flat in
    # the contact's plane, inside its rectangle
    sides = np.sort(np.concatenate([ones, interface_element.reshape(-1)]))
    points = vertices[np.maximum(face[sides], 0)]
    valid = face[sides] >= 0
    factor = mesh.grid // layout.steps
    contact_of = np.full(len(sides), -1, dtype=np.int64)
    for c, (axis, value, (p0, p1), (q0, q1)) in enumerate(layout.contacts):
        b, d = (axis + 1) % 3, (axis + 2) % 3
        on = np.all(~valid | (points[:, :, axis] == value * factor), axis=1)
        on &= np.all(~valid | ((points[:, :, b] >= p0 * factor) & (points[:, :, b] <= p1 * factor)
                               & (points[:, :, d] >= q0 * factor) & (points[:, :, d] <= q1 * factor)), axis=1)
        region = [r.name for r in layout.device.regions].index(layout.device.contacts[c].region)
        on &= element_region[element[sides]] == region
        contact_of[on & (contact_of < 0)] = c
    hit = contact_of >= 0
    outer = face[ones]
    lower = interface_element[:, 0]
    return RegionFaces(face[sides[hit]].astype(np.int32), element[sides[hit]], contact_of[hit].astype(np.int32),
                       interfaces.astype(np.int32), names, face[lower].astype(np.int32),
                       np.stack([element[lower], element[interface_element[:, 1]]], axis=1),
                       which.astype(np.int32).reshape(-1), edge_keys(outer, len(mesh.vertices)),
                       outer.astype(np.int32))


def face_sets(element: np.ndarray, polygons: list[np.ndarray], element_region: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Every element face paired by its vertices: the faces met once, and those between two regions.

    ``element``: each face's element; ``polygons``: blocks of faces (rows of vertex ids,
    counter-clockwise seen from outside their element; all blocks' rows in ``element``'s
    order).  Returns the faces (-1 padded) and their elements, sorted by vertex set; the
    indices into them of the faces met once; per interface face the indices of its two
    occurrences (the lower region's first, as the face is oriented out of it: the interface
    polygon); the interfaces (region pairs ``a < b``) and each interface face's interface.
    The mesher's faces and check's (from a file's elements) are sorted by this one rule.
    """
    width = max(p.shape[1] for p in polygons)
    element = np.asarray(element, dtype=np.int64)
    face = np.concatenate([np.pad(p, ((0, 0), (0, width - p.shape[1])), constant_values=-1) for p in polygons])
    key = np.sort(np.where(face < 0, np.iinfo(np.int32).max, face), axis=1)
    order = np.lexsort(key.T[::-1])
    key, element, face = key[order], element[order], face[order]
    same = np.all(key[1:] == key[:-1], axis=1)
    first = np.r_[True, ~same]
    last = np.r_[~same, True]
    single = first & last
    paired = np.flatnonzero(first & ~last)  # the first of each pair (a conforming mesh has no more)
    # interfaces: pairs of elements of different regions
    ra, rb = element_region[element[paired]], element_region[element[paired + 1]]
    across = ra != rb
    pa, pb = paired[across], paired[across] + 1
    swap = element_region[element[pa]] > element_region[element[pb]]
    lower = np.where(swap, pb, pa)
    upper = np.where(swap, pa, pb)
    pairs = np.stack([element_region[element[lower]], element_region[element[upper]]], axis=1)
    interfaces, which = (np.unique(pairs, axis=0, return_inverse=True) if len(pairs)
                         else (np.zeros((0, 2), np.int64), np.zeros(0, np.int64)))
    return element, face, np.flatnonzero(single), np.stack([lower, upper], axis=1), interfaces, \
        which.reshape(-1)


def _on_a_plane(vertices: np.ndarray, polygon: np.ndarray, in_plane: np.ndarray, on_some_plane: np.ndarray
                ) -> np.ndarray:
    """Which faces (rows of vertex ids) lie flat in one of the device's block planes.

    ``in_plane[v, a]``: whether vertex ``v``'s coordinate along axis ``a`` is one of the
    block planes normal to ``a`` (``on_some_plane``: along any axis).  Only those faces can be a contact or interface face or
    lie on the domain's boundary (every box face lies in a block plane), and both copies
    of a shared face are kept: what is paired among them is paired as among all faces,
    at a fraction of the sort.  A face whose first corner lies on no plane is out at once.
    """
    first = polygon[:, 0]
    candidates = np.flatnonzero(on_some_plane[first])
    on = np.zeros(len(polygon), dtype=bool)
    for axis in range(3):
        rows = candidates[in_plane[first[candidates], axis]]
        flat = np.all(vertices[polygon[rows], axis] == vertices[first[rows], axis, None], axis=1)
        on[rows[flat]] = True
    return on


def contact_areas(mesh: Mesh, faces: RegionFaces) -> list[Fraction]:
    """Each contact's area from its faces, exactly, in device units (the polygons' shoelace areas)."""
    _, layout, _ = device_of(mesh)
    lengths = [high - low for low, high in layout.device.bounds]
    areas = [Fraction(0)] * len(layout.contacts)
    vertices = mesh.vertices.astype(np.int64)
    for c, (axis, _, _, _) in enumerate(layout.contacts):
        b, d = (axis + 1) % 3, (axis + 2) % 3
        polygons = faces.contact_nodes[faces.contact_face_contact == c]
        valid = polygons >= 0
        # each vertex with the next one of its polygon (the first after the last)
        following = np.roll(polygons, -1, axis=1)
        following = np.where(following >= 0, following, polygons[:, :1])
        x, y = vertices[np.maximum(polygons, 0), b], vertices[np.maximum(polygons, 0), d]
        nx, ny = vertices[np.maximum(following, 0), b], vertices[np.maximum(following, 0), d]
        twice = np.abs(np.where(valid, x * ny - nx * y, 0).sum(axis=1))  # below 2 * grid**2 each
        areas[c] = Fraction(int(twice.sum()), 2 * mesh.grid ** 2) * lengths[b] * lengths[d]
    return areas



@dataclass(frozen=True)
class _Vertices:
    """What :func:`~cospherical.mesh.dual.mesh_dual` reads of a mesh when it is given the elements."""

    box: Box
    grid: int
    vertices: np.ndarray


def region_parts(box: Box, grid: int, vertices: np.ndarray, dual: Dual, element_region: np.ndarray,
                 names: tuple[str, ...], materials: tuple[str, ...],
                 contacts: tuple[tuple[str, int, tuple[str, ...], int], ...] = (),
                 contact_face_nodes: np.ndarray | None = None, contact_face_contact: np.ndarray | None = None,
                 lengths: tuple[Fraction, Fraction, Fraction] | None = None,
                 origin: Sequence[object] = ("0", "0", "0"), region_duals: list[Dual] | None = None,
                 boxes: tuple[tuple[tuple[str, ...], ...], ...] = ()) -> RegionParts:
    """The dual of each region's elements alone (exact), as parts of ``dual`` (see :class:`RegionParts`).

    A region's part of a control volume or of a coupling is the dual of its own
    elements (:func:`~cospherical.mesh.dual.mesh_dual` on them): the box method's
    element pieces add up, so the parts of every vertex and edge sum to its total
    exactly.  ``contacts``: per contact ``(name, region index, box texts, axis)``, with
    its faces; a face's area goes to its vertices as the box method's boundary pieces
    do (the triangles between each vertex, its edges' midpoints and the face's circle
    centre), exactly; ``lengths``: the bounding box's rational lengths.  ``region_duals``:
    each region's dual when the caller has it (:func:`mesh_region_parts` computes it leaf
    configuration by configuration, much faster than from the element list).
    """
    keys = dual.edges[:, 0].astype(np.int64) * len(vertices) + dual.edges[:, 1]
    mesh = _Vertices(box, grid, vertices)
    vv: list[np.ndarray] = []
    vr: list[np.ndarray] = []
    ve: list[np.ndarray] = []
    ce: list[np.ndarray] = []
    cr: list[np.ndarray] = []
    cx: list[np.ndarray] = []
    vden: list[int] = []
    cden: list[int] = []
    for r in range(len(names)):
        rows = np.flatnonzero(element_region == r)
        whole = len(rows) == len(element_region)  # one region holds every element: no copy of the arrays
        nodes = dual.element_nodes if whole else dual.element_nodes[rows]
        part = region_duals[r] if region_duals is not None else \
            mesh_dual(mesh, (nodes, dual.element_sizes if whole else dual.element_sizes[rows]))
        used = np.flatnonzero(np.asarray(part.volume_exact != 0) | _used(nodes, len(vertices)))
        vv.append(used)
        vr.append(np.full(len(used), r, dtype=np.int32))
        ve.append(part.volume_exact[used])
        vden.append(part.volume_denominator)
        edge = np.arange(len(keys)) if part is dual else \
            np.searchsorted(keys, part.edges[:, 0].astype(np.int64) * len(vertices) + part.edges[:, 1])
        ce.append(edge)
        cr.append(np.full(len(edge), r, dtype=np.int32))
        cx.append(part.coefficient_exact)
        cden.append(part.coefficient_denominator)
    volume_denominator, coupling_denominator = math.lcm(*vden), math.lcm(*cden)
    volume_exact = _common(ve, vden, volume_denominator)
    coupling_exact = _common(cx, cden, coupling_denominator)
    volume_vertex, volume_region = np.concatenate(vv), np.concatenate(vr)
    coupling_edge, coupling_region = np.concatenate(ce), np.concatenate(cr)
    # one region's rows are sorted already (increasing vertices, increasing edges)
    order = np.lexsort((volume_region, volume_vertex)) if len(names) > 1 else slice(None)
    corder = np.lexsort((coupling_region, coupling_edge)) if len(names) > 1 else slice(None)
    if contact_face_nodes is None or contact_face_contact is None:
        contact_face_nodes = np.zeros((0, 3), dtype=np.int32)
        contact_face_contact = np.zeros(0, dtype=np.int32)
    contact_vertex, contact_contact, contact_exact, contact_denominator = vertex_parts(
        vertices, contact_face_nodes, contact_face_contact, len(contacts), grid,
        lengths or (Fraction(1), Fraction(1), Fraction(1)))
    return RegionParts(
        tuple(names), tuple(materials), element_region.astype(np.int32, copy=False),
        volume_vertex[order].astype(np.int64, copy=False), volume_region[order], volume_exact[order], volume_denominator,
        coupling_edge[corder].astype(np.int64, copy=False),
        coupling_region[corder],
        coupling_exact[corder], coupling_denominator, tuple(c[0] for c in contacts), tuple(c[1] for c in contacts),
        tuple(tuple(c[2]) for c in contacts), contact_face_nodes.astype(np.int32),
        contact_face_contact.astype(np.int32), contact_vertex.astype(np.int64), contact_contact.astype(np.int32),
        _narrow_array(contact_exact) if contact_exact.dtype != object else _narrow(contact_exact.tolist()),
        contact_denominator, dual.volume_factor,
        tuple(str(x) for x in origin), boxes)


def _used(nodes: np.ndarray, count: int) -> np.ndarray:
    used = np.zeros(count, dtype=bool)
    used[nodes[nodes >= 0]] = True
    return used


def _narrow_array(values: np.ndarray) -> np.ndarray:
    """What :func:`_narrow` makes of int64 values, without a Python list."""
    if len(values) and int(np.abs(values).max()) >= 2**62 // len(values):
        return np.array(values.tolist(), dtype=object).reshape(-1)
    return values.astype(np.int64).reshape(-1)


def _narrow(values: list[int]) -> np.ndarray:
    """Integers as int64 when they fit with room for sums, else Python integers (object)."""
    fits = all(abs(v) < 2**62 // max(1, len(values)) for v in values)
    return np.array(values, dtype=np.int64 if fits else object).reshape(-1)


def _common(parts: list[np.ndarray], denominators: list[int], common: int) -> np.ndarray:
    """Numerators over their own denominators, brought over one ``common`` denominator (exact).

    What :func:`_narrow` makes of the Python integers, computed in int64 when every scaled
    value fits with room for sums (the bound is checked on each part's largest value).
    """
    room = 2**62 // max(1, sum(len(part) for part in parts))
    if all(part.dtype != object and (not len(part) or int(np.abs(part).max()) * (common // d) < room)
           for part, d in zip(parts, denominators)):
        if len(parts) == 1 and common == denominators[0]:  # one region's: the numerators as they are, no copy
            return parts[0].astype(np.int64, copy=False)
        return np.concatenate([part.astype(np.int64) * np.int64(common // d) for part, d in zip(parts, denominators)]
                              + [np.zeros(0, dtype=np.int64)])
    return _narrow([int(x) * (common // d) for part, d in zip(parts, denominators) for x in part.tolist()])


def mesh_region_parts(mesh: Mesh, dual: Dual, faces: RegionFaces) -> RegionParts:
    """:func:`region_parts` of a device mesh, its contacts from ``faces``."""
    regions, layout, element_region = device_of(mesh)
    device = layout.device
    names = [r.name for r in device.regions]
    contacts = tuple((c.name, names.index(c.region), tuple(str(x) for x in c.box), c.axis) for c in device.contacts)
    (x0, x1), (y0, y1), (z0, z1) = device.bounds
    lengths = (x1 - x0, y1 - y0, z1 - z0)
    # one region holds every element: its dual is the mesh's (computing it again cost a fifth of a diode's run)
    duals = [dual] if len(names) == 1 else [mesh_dual(_region_mesh(mesh, r)) for r in range(len(names))]
    return region_parts(mesh.box, mesh.grid, mesh.vertices, dual, element_region, regions.names,
                        regions.materials, contacts, faces.contact_nodes, faces.contact_face_contact, lengths,
                        device.origin, duals,
                        tuple(tuple(tuple(str(x) for x in box) for box in r.boxes) for r in device.regions))


def _region_mesh(mesh: Mesh, region: int) -> Mesh:
    """The mesh of one region's elements alone (the other leaves marked replaced, the other cells left out)."""
    leaf_region = device_of(mesh)[0].leaf_region
    other = leaf_region != region
    if mesh.replaced is not None:
        other = other | mesh.replaced
    cells = mesh.cells
    if cells is None:
        cells = Cells([], np.zeros(0, np.int32), np.zeros((0, 3), np.int64), np.zeros((0, 4), np.int32),
                      np.zeros(0, np.int64), np.zeros(0, bool), np.zeros(0, bool))
    rows = np.flatnonzero(leaf_region[cells.leaf] == region)
    mine = Cells(cells.shapes, cells.shape[rows], cells.anchor[rows], cells.nodes[rows], cells.leaf[rows],
                 cells.spanning[rows], cells.proven[rows], cells.clusters, cells.largest_cluster)
    return with_cells(mesh, other, mine, mesh.types)


def region_volumes(mesh: Mesh) -> list[Fraction]:
    """Each region's elements' volume, exactly, as a fraction of the root box's volume."""
    regions, _, _ = device_of(mesh)
    count = len(regions.names)
    depth = mesh.tree.depth
    volumes = [Fraction(0)] * count
    leaf_region = regions.leaf_region
    for _, tessellation, leaves in mesh.groups():
        unit = sum((e.unit_volume for e in tessellation.elements), Fraction(0))
        weight = 8 ** (depth - mesh.tree.levels[leaves].astype(np.int64))
        for r, total in enumerate(np.bincount(leaf_region[leaves], weights=None, minlength=count).tolist()):
            if total:
                volumes[r] += unit * int(weight[leaf_region[leaves] == r].sum()) / 8 ** depth
    if mesh.cells is not None:
        cell_region = leaf_region[mesh.cells.leaf]
        for s, shape in enumerate(mesh.cells.shapes):
            for r in np.unique(cell_region[mesh.cells.shape == s]).tolist():
                n = int(((mesh.cells.shape == s) & (cell_region == r)).sum())
                volumes[r] += shape.grid_volume * n / mesh.grid ** 3
    return volumes


def device_report(mesh: Mesh, faces: RegionFaces, dual: Dual | None = None) -> DeviceSummary:
    """The report's ``device`` section: per region its elements, nodes, volume (exact) and, with the dual
    (its parts per region computed), its negative coefficients (interior: off the domain's boundary) and
    control volume sum; per contact its faces, nodes, area; per interface its faces and nodes."""
    _, layout, element_region = device_of(mesh)
    device = layout.device
    lengths = [high - low for low, high in device.bounds]
    box_volume = lengths[0] * lengths[1] * lengths[2]
    volumes = region_volumes(mesh)
    # per region its elements and the vertices they use, block by block (no whole connectivity table)
    count = len(device.regions)
    elements = np.bincount(element_region, minlength=count)
    used = np.zeros((count, len(mesh.vertices)), dtype=bool)
    for element_rows, nodes, _, _ in mesh.blocks():
        used[np.repeat(element_region[element_rows], nodes.shape[1]), nodes.reshape(-1)] = True
    negative = None
    parts = dual.regions if dual is not None else None
    if dual is not None and parts is not None:
        factor = _factor(dual)
        if dual.boundary_edge is None:
            raise ValueError("device_report: a device's dual without its boundary edges (pipeline.full_dual sets them)")
        on_boundary = dual.boundary_edge[parts.coupling_edge]
        below = np.asarray(parts.coupling_exact < 0)
        negative = [NegativeCoefficients(int((below & ~on_boundary & (parts.coupling_region == r)).sum()),
                                         int((below & on_boundary & (parts.coupling_region == r)).sum()))
                    for r in range(len(device.regions))]
    regions = []
    for r, region in enumerate(device.regions):
        with_dual = negative is not None and parts is not None  # the region's dual figures
        regions.append(RegionSummary(
            region.name, region.material, int(elements[r]), int(used[r].sum()), str(volumes[r] * box_volume),
            volumes[r] * box_volume == layout.region_volumes[r],
            negative[r] if with_dual and negative is not None else None,
            str(parts.region_volumes()[r] * factor) if with_dual and parts is not None else None))
    areas = contact_areas(mesh, faces)
    contacts = []
    for c, contact in enumerate(device.contacts):
        box = contact.box
        axis = contact.axis
        b, d = (axis + 1) % 3, (axis + 2) % 3
        expected = (box[b + 3] - box[b]) * (box[d + 3] - box[d])
        contacts.append(ContactSummary(
            contact.name, contact.region, int((faces.contact_face_contact == c).sum()),
            int(len(faces.contact_vertices(c))), str(areas[c]), areas[c] == expected,
            str(parts.contact_areas()[c]) if parts is not None else None))
    interfaces = []
    for i, name in enumerate(faces.interface_names):
        nodes = faces.interface_nodes[faces.interface_face_interface == i]
        interfaces.append(InterfaceSummary(name, int(len(nodes)), int(len(np.unique(nodes[nodes >= 0])))))
    x, y, z = (str(v) for v in device.origin)
    return DeviceSummary(device.name, layout.resolving_level, mesh.tree.depth, (x, y, z), tuple(regions),
                         tuple(contacts), tuple(interfaces))


def _factor(dual: Dual) -> Fraction:
    """The dual's volume factor ``a*b*c`` as an exact fraction (a device's lengths are rational)."""
    squared = Fraction(dual.volume_factor_squared)
    root = Fraction(math.isqrt(squared.numerator), math.isqrt(squared.denominator))
    assert root * root == squared
    return root
