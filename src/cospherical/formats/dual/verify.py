"""Verifying a ``dual.npz``: its dual computed again from its vertices and elements and compared exactly, its
elements proved a mesh of the domain, a device's regions, contacts and interfaces checked."""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from ...core.configuration import Box
from ...errors import FormatError, InputError, shown
from ...files.yamlio import machine_memory
from ...mesh.device import DeviceLayout
from ...mesh.dual import Dual, RegionParts

__all__ = ["domain_sums", "dual_layout", "verify_dual"]

# The exact work of verifying: a hull per distinct element shape, which tries every triple of its
# vertices (about 2 microseconds a triple; 0.1 CPU-s at 64 vertices). A file of many distinct large
# shapes would take hours, so their triples are bounded before any hull: a fixed allowance (about 2
# CPU-s) and so many per element (our meshes need a few: the results page's 50,912 elements are 363
# shapes of at most 8 vertices, 3,660 triples), which keeps the hulls within a few times the rest.
_TRIPLES_ALLOWED = 1_000_000
_TRIPLES_PER_ELEMENT = 100


@dataclass(frozen=True)
class _Vertices:
    """What :func:`~cospherical.mesh.dual.mesh_dual` reads of a mesh when it is given the elements."""

    box: Box
    grid: int
    vertices: np.ndarray


def _distinct_vertices(vertices: np.ndarray, path: str | Path) -> None:
    """Refuse two vertices at one grid point: an element holding both has an edge of length 0,
    which no dual has (its coefficient would divide by it)."""
    order = np.lexsort(vertices.T[::-1])
    same = np.flatnonzero(np.all(vertices[order[1:]] == vertices[order[:-1]], axis=1))
    if len(same):
        i, j = sorted(int(v) for v in order[same[0]:same[0] + 2])
        raise FormatError(f"{path}: member grid_vertices: vertices {i} and {j} are one grid point "
                          f"{vertices[i].tolist()}")


def _element_shapes(dual: Dual, path: str | Path) -> np.ndarray:
    """Each element's shape: a number equal for elements whose vertices, node for node, are translates of
    each other; from the vertex ids alone.  Elements whose distinct shapes need more exact hull work than
    :data:`_TRIPLES_ALLOWED` and :data:`_TRIPLES_PER_ELEMENT` allow (see there) are refused first.

    Shapes are told apart up to translation, finer than the dual's grouping (which also divides out
    a power of two), so the work counted is never less than the work done.
    """
    nodes, vertices = dual.element_nodes, dual.grid_vertices
    allowed = _TRIPLES_ALLOWED + _TRIPLES_PER_ELEMENT * len(nodes)
    seen: dict[bytes, int] = {}
    shape = np.empty(len(nodes), dtype=np.int64)
    triples = 0
    step = max(1, (1 << 17) // nodes.shape[1])  # elements per block: 3 MB of coordinates (24 bytes a vertex)
    for start in range(0, len(nodes), step):
        block = nodes[start:start + step].astype(np.int64)
        used = block >= 0
        coords = vertices[np.where(used, block, 0)]
        low = np.where(used[..., None], coords, np.iinfo(np.int64).max).min(axis=1)
        relative = np.where(used[..., None], coords - low[:, None, :], -1).reshape(len(block), -1)
        rows = np.ascontiguousarray(relative).view(np.dtype((np.void, relative.shape[1] * 8))).ravel()
        distinct, inverse = np.unique(rows, return_inverse=True)  # as raw bytes: ten times faster than axis=0
        numbers = np.empty(len(distinct), dtype=np.int64)
        for k, row in enumerate(distinct):
            key = row.tobytes()
            if key not in seen:
                seen[key] = len(seen)
                triples += math.comb(int((np.frombuffer(key, dtype=np.int64)[::3] >= 0).sum()), 3)
                if triples > allowed:
                    raise FormatError(f"{path}: member element_nodes: {len(seen):,} distinct element shapes whose "
                                      f"exact hulls are more work than {len(nodes):,} elements may need "
                                      f"({triples:,} vertex triples, at most {allowed:,})")
            numbers[k] = seen[key]
        shape[start:start + len(block)] = numbers[inverse.reshape(-1)]
    return shape


def _check_mesh(dual: Dual, shape: np.ndarray, path: str | Path, layout: DeviceLayout | None = None,
                element_region: np.ndarray | None = None) -> tuple[Any, ...] | None:
    """The elements are a mesh of the domain: every face met by exactly two elements, in opposite
    orientations, or by one in the domain's boundary
    (:func:`~cospherical.mesh.checks.pair_faces`, the mesher's own conformity rule).

    With positive volumes (every element is the hull of its vertices: not flat) and volumes
    adding up to the domain's (the control volumes, recomputed from the elements, sum to it),
    this proves that the elements tile the domain: crossing a face met from both sides keeps
    the number of elements over a point, so that number is the same all over the domain, and
    the volumes make it one.  Volume sums alone cannot see elements that overlap and leave a
    hole of the same volume.

    With ``element_region`` (a version 5 device), returns the faces paired by
    :func:`~cospherical.mesh.regions.face_sets` (the boundary's and the interfaces'), else ``None``.
    """
    from ...mesh.checks import element_faces, pair_faces
    from ...mesh.regions import face_sets

    owners: dict[int, list[np.ndarray]] | None = {} if element_region is not None else None
    try:
        faces = element_faces(dual.grid_vertices, dual.element_nodes, dual.element_sizes, shape, dual.box.squared,
                              machine_memory() // 2, owners=owners)
    except InputError as error:
        raise FormatError(f"{path}: member element_nodes: {error}") from None
    sets = None
    if owners is not None and element_region is not None:
        sizes = list(faces)
        sets = face_sets(np.concatenate([m for size in sizes for m in owners[size]]),
                         [f for size in sizes for f in faces[size]], element_region)
    found = pair_faces(faces, dual.grid_vertices, dual.grid, examples=1, layout=layout)
    if found.nonconforming_faces:
        corners = [[round(x * dual.grid) for x in corner] for corner in found.nonconforming_examples[0]]
        raise FormatError(f"{path}: member element_nodes: the elements are not a mesh: {found.nonconforming_faces:,} "
                          "faces are neither shared by two elements in opposite orientations nor in the domain's "
                          f"boundary, e.g. the face of grid points {', '.join(map(str, corners[:6]))}"
                          f"{', ...' if len(corners) > 6 else ''}")
    return sets


def verify_dual(dual: Dual, path: str | Path) -> None:
    """Compute ``dual`` again from its vertices and elements and compare, exactly (see the module).

    Raises :class:`FormatError` (one line) at the first difference: an edge, a vertex, or a
    float member that is not what its exact value gives.
    """
    from ...mesh.dual import as_floats, boundary_areas, mesh_dual
    from ...mesh.surfaces import set_domain_boundary

    _distinct_vertices(dual.grid_vertices, path)
    shape = _element_shapes(dual, path)
    layout = dual_layout(dual, path)
    interfaces = dual.regions.interfaces if dual.regions is not None else None
    if layout is not None and dual.regions is not None:
        _check_element_regions(dual, dual.regions, layout, path)
    sets = _check_mesh(dual, shape, path, layout,
                       dual.regions.element_region if dual.regions is not None and interfaces is not None else None)
    try:
        again = mesh_dual(_Vertices(dual.box, dual.grid, dual.grid_vertices), (dual.element_nodes, dual.element_sizes))
    except InputError as error:  # an element that is flat or not co-spherical has no dual
        raise FormatError(f"{path}: member element_nodes: {error}") from None
    if sets is not None:  # a version 5 device: its boundary is the faces met once (4: the bounding box's sides)
        _verify_interfaces(dual, sets, path)
        _, face, ones, _, _, _ = sets
        set_domain_boundary(again, face[ones])
    if not np.array_equal(again.edges, dual.edges):
        raise FormatError(f"{path}: member edges: not the edges of its elements ({len(dual.edges)} edges, "
                          f"its elements have {len(again.edges)})")
    g = dual.grid_vertices

    def first(where: np.ndarray) -> int:
        return int(np.flatnonzero(where)[0])

    def different(ours: np.ndarray, our_denominator: int, theirs: np.ndarray, their_denominator: int) -> np.ndarray:
        # a / d == b / e  <=>  a e == b d: Python integers, no overflow; over one denominator (the file's
        # are what a recomputation gives, unless altered) int64 numerators are compared as they are
        if our_denominator == their_denominator and ours.dtype == theirs.dtype == np.int64:
            left, right = ours, theirs
        else:
            left = ours.astype(object) * their_denominator
            right = theirs.astype(object) * our_denominator
        unequal: np.ndarray = np.asarray(np.asarray(left != right).reshape(len(ours), -1).any(axis=1))
        return unequal

    wrong = different(again.coefficient_exact, again.coefficient_denominator, dual.coefficient_exact,
                      dual.coefficient_denominator)
    if wrong.any():
        i, j = dual.edges[first(wrong)]
        raise FormatError(f"{path}: member coefficient_exact: edge {i}-{j} (grid points {g[i].tolist()}, "
                          f"{g[j].tolist()}) is not the coefficient its elements give")
    for name, ours, theirs in (("volume_exact", (again.volume_exact, again.volume_denominator),
                                (dual.volume_exact, dual.volume_denominator)),
                               ("boundary_area_exact", (again.boundary_area_exact, again.boundary_area_denominator),
                                (dual.boundary_area_exact, dual.boundary_area_denominator))):
        wrong = different(*ours, *theirs)
        if wrong.any():
            v = first(wrong)
            raise FormatError(f"{path}: member {name}: vertex {v} (grid point {g[v].tolist()}) is not what its "
                              "elements give")
    # the floats: what the writer computes from the file's own exact values, bit for bit
    lengths = np.array(dual.box.to_float())
    real = g * (lengths / dual.grid)
    edge_vectors = real[dual.edges[:, 1]] - real[dual.edges[:, 0]]
    length = np.sqrt((edge_vectors ** 2).sum(axis=1))
    coefficient = as_floats(dual.coefficient_exact, dual.coefficient_denominator, dual.volume_factor)
    expected = {"vertices": real, "length": length, "coefficient": coefficient, "area": coefficient * length,
                "control_volume": as_floats(dual.volume_exact, dual.volume_denominator, dual.volume_factor),
                "boundary": again.boundary,
                "boundary_area": boundary_areas(dual.boundary_area_exact, dual.boundary_area_denominator,
                                                dual.boundary_factors_squared)}
    for name, value in expected.items():
        wrong = np.asarray(np.asarray(getattr(dual, name) != value).reshape(len(value), -1).any(axis=1))
        if wrong.any():
            k = first(wrong)
            what = f"edge {dual.edges[k, 0]}-{dual.edges[k, 1]}" if len(value) == len(dual.edges) and name in (
                "length", "coefficient", "area") else f"vertex {k}"
            raise FormatError(f"{path}: member {name}: {what} is not what the exact values give")
    if dual.regions is not None:
        _verify_regions(dual, dual.regions, path)
    if sets is not None:
        dual.boundary_edge = again.boundary_edge  # verified: the edges in the boundary, which the file does not hold


def _check_element_regions(dual: Dual, parts: RegionParts, layout: DeviceLayout, path: str | Path) -> None:
    """Each element's region is the region of the box it lies in: the owner of the block holding its vertex
    centroid (an interior point; decided in integers, the centroid times the element's size against the block
    planes).  The parts check recomputes from ``element_region``; this proves ``element_region`` itself."""
    nodes, sizes = dual.element_nodes.astype(np.int64), dual.element_sizes.astype(np.int64)
    factor = dual.grid // layout.steps  # grid steps per step of the resolving level
    sums = np.where((nodes >= 0)[..., None], dual.grid_vertices[np.maximum(nodes, 0)], 0).sum(axis=1)
    owner = np.empty(len(nodes), dtype=np.int64)
    for size in np.unique(sizes).tolist():
        rows = np.flatnonzero(sizes == size)
        index = tuple(np.clip(np.searchsorted(layout.planes[a] * factor * size, sums[rows, a], "right") - 1, 0,
                              len(layout.planes[a]) - 2) for a in range(3))
        owner[rows] = layout.owner[index]
    wrong = np.flatnonzero(owner != parts.element_region)
    if len(wrong):
        e = int(wrong[0])
        names = parts.names
        lies = f"in a box of region {shown(names[owner[e]])}" if owner[e] >= 0 else "outside every region's box"
        raise FormatError(f"{path}: member element_region: element {e} is given region "
                          f"{shown(names[parts.element_region[e]])} but lies {lies}")


def dual_layout(dual: Dual, path: str | Path) -> DeviceLayout | None:
    """A version 4 or 5 file's device geometry (its regions' boxes and its contacts) checked again and cut into
    blocks (:class:`~cospherical.mesh.device.DeviceLayout`), or ``None`` for a one-box dual; its bounding box
    must be the file's domain, its low corner the file's origin."""
    from ...mesh.device import Contact, Device, Region, device_layout

    parts = dual.regions
    if parts is None:
        return None
    try:
        regions = tuple(Region(name, material, tuple(_six(box) for box in boxes))
                        for name, material, boxes in zip(parts.names, parts.materials, parts.boxes))
        contacts = tuple(Contact(name, parts.names[r], _six(box))
                         for name, r, box in zip(parts.contact_names, parts.contact_regions, parts.contact_boxes))
        device = Device("dual", regions, contacts, (), 0)
        layout = device_layout(device)
    except (InputError, ValueError, ZeroDivisionError) as error:
        raise FormatError(f"{path}: manifest: the device's boxes: {str(error)[:200]}") from None
    if tuple(str(high - low) for low, high in device.bounds) != tuple(dual.box.texts) or \
            tuple(device.origin) != tuple(Fraction(x) for x in parts.origin):
        raise FormatError(f"{path}: manifest: the device's boxes do not span its domain from its origin")
    return layout


def _six(texts: tuple[str, ...]) -> tuple[Fraction, Fraction, Fraction, Fraction, Fraction, Fraction]:
    """A box's six exact texts (low corner, high corner) as fractions; ValueError unless six numbers."""
    x0, y0, z0, x1, y1, z1 = (Fraction(x) for x in texts)
    return x0, y0, z0, x1, y1, z1


def domain_sums(layout: DeviceLayout, whole: bool = True) -> tuple[Fraction, tuple[Fraction, Fraction, Fraction]]:
    """What a device's control volumes and boundary areas sum to: its volume as a fraction of the bounding
    box's, and per axis the area of its boundary normal to it as a fraction of one side of the bounding
    box (``whole=False``: only the boundary in the bounding box's two sides, as a version 4 file counts it)."""
    steps = [np.diff(p) for p in layout.planes]
    inside = layout.owner >= 0
    volume = Fraction(int((inside * steps[0][:, None, None] * steps[1][None, :, None]
                           * steps[2][None, None, :]).sum()), layout.steps ** 3)
    sides = []
    for axis in range(3):
        b, c = [a for a in range(3) if a != axis]
        area = np.outer(steps[b], steps[c])
        layers = np.moveaxis(inside, axis, 0)
        if whole:  # a block face with the domain on one side only, at every plane
            padded = np.pad(layers, ((1, 1), (0, 0), (0, 0)))
            faces = padded[1:] != padded[:-1]
        else:
            faces = np.stack([layers[0], layers[-1]])
        sides.append(Fraction(int((faces * area).sum()), layout.steps ** 2))
    return volume, (sides[0], sides[1], sides[2])


def _verify_regions(dual: Dual, parts: RegionParts, path: str | Path) -> None:
    """A version 4 or 5 file's region parts computed again from its elements, their regions and its contact faces,
    and compared exactly; each contact's faces lie in its rectangle and cover its area exactly."""
    from ...mesh.regions import region_parts

    boxes = [tuple(Fraction(x) for x in box) for box in parts.contact_boxes]
    try:
        length_a, length_b, length_c = (Fraction(text) for text in dual.box.texts)
        lengths = (length_a, length_b, length_c)
    except ValueError:
        raise FormatError(f"{path}: manifest: a device's domain lengths must be rational") from None
    axes = []
    for c, box in enumerate(boxes):
        flat = [a for a in range(3) if box[a] == box[a + 3]]
        if len(flat) != 1:
            raise FormatError(f"{path}: manifest: contact {c}'s box is not a rectangle")
        axes.append(flat[0])
    contacts = tuple((name, region, tuple(box), axis) for name, region, box, axis in
                     zip(parts.contact_names, parts.contact_regions, parts.contact_boxes, axes))
    try:
        again = region_parts(dual.box, dual.grid, dual.grid_vertices, dual, parts.element_region, parts.names,
                             parts.materials, contacts, parts.contact_face_nodes, parts.contact_face_contact, lengths,
                             parts.origin)
    except InputError as error:  # a face off the coordinate planes, or whose first three vertices are on a line
        raise FormatError(f"{path}: member contact_face_nodes: a contact face is no polygon in a coordinate "
                          f"plane ({error})") from None

    def rows_differ(name: str, ours: tuple[tuple[np.ndarray, ...], np.ndarray, int],
                    theirs: tuple[tuple[np.ndarray, ...], np.ndarray, int]) -> None:
        (a_index, a_values, a_den), (b_index, b_values, b_den) = ours, theirs
        if len(a_index[0]) != len(b_index[0]) or any(not np.array_equal(x, y) for x, y in zip(a_index, b_index)):
            raise FormatError(f"{path}: member {name}: not the rows its elements give ({len(b_index[0])} rows, "
                              f"its elements give {len(a_index[0])})")
        left = a_values.astype(object) * b_den
        right = b_values.astype(object) * a_den
        wrong = np.flatnonzero(np.asarray(left != right).reshape(-1))
        if len(wrong):
            k = int(wrong[0])
            raise FormatError(f"{path}: member {name}_exact: row {k} ({' '.join(str(int(i[k])) for i in a_index)}) "
                              "is not the part its elements give")

    rows_differ("volume_part", ((again.volume_vertex, again.volume_region), again.volume_exact,
                                again.volume_denominator),
                ((parts.volume_vertex, parts.volume_region), parts.volume_exact, parts.volume_denominator))
    rows_differ("coupling_part", ((again.coupling_edge, again.coupling_region), again.coupling_exact,
                                  again.coupling_denominator),
                ((parts.coupling_edge, parts.coupling_region), parts.coupling_exact, parts.coupling_denominator))
    rows_differ("contact_part", ((again.contact_vertex, again.contact_contact), again.contact_exact,
                                 again.contact_denominator),
                ((parts.contact_vertex, parts.contact_contact), parts.contact_exact, parts.contact_denominator))
    # each contact: its faces in its rectangle, their areas the rectangle's (exact, on the grid)
    g = dual.grid_vertices
    origin = [Fraction(x) for x in parts.origin]
    for c, (box, axis) in enumerate(zip(boxes, axes)):
        b, d = (axis + 1) % 3, (axis + 2) % 3
        rectangle = [(box[i] - origin[i % 3]) / lengths[i % 3] * dual.grid for i in range(6)]
        twice = 0
        for face in parts.contact_face_nodes[parts.contact_face_contact == c]:
            p = g[face[face >= 0]].astype(np.int64)
            if not all(rectangle[a] <= int(v) <= rectangle[a + 3] for a in range(3) for v in p[:, a]):
                raise FormatError(f"{path}: member contact_face_nodes: a face of contact "
                                  f"{shown(parts.contact_names[c])} leaves its rectangle")
            x, y = p[:, b], p[:, d]
            twice += abs(int((x * np.roll(y, -1) - np.roll(x, -1) * y).sum()))
        area = Fraction(twice, 2 * dual.grid ** 2) * lengths[b] * lengths[d]
        if area != (box[b + 3] - box[b]) * (box[d + 3] - box[d]):
            raise FormatError(f"{path}: contact {shown(parts.contact_names[c])}: its faces' area {area} is not its "
                              "rectangle's")
    _contact_faces_on_elements(dual, parts, path)


def _contact_faces_on_elements(dual: Dual, parts: RegionParts, path: str | Path) -> None:
    """Each contact face lies on an element of its contact's region: its vertices are that element's (in the
    contact's flat rectangle, checked before, they are the element's face there).  A polygon of the file's own
    (one quad over a whole contact) or a contact naming a region that does not touch it is refused."""
    nodes = dual.element_nodes.astype(np.int64)
    owner = np.repeat(np.arange(len(nodes)), nodes.shape[1])  # vertex -> elements, through one sort
    flat = nodes.reshape(-1)
    order = np.argsort(flat, kind="stable")
    keys, owners = flat[order], owner[order]
    for k, (face, c) in enumerate(zip(parts.contact_face_nodes.tolist(), parts.contact_face_contact.tolist())):
        ids = [v for v in face if v >= 0]
        low, high = np.searchsorted(keys, ids[0], "left"), np.searchsorted(keys, ids[0], "right")
        candidates = owners[low:high]
        candidates = candidates[parts.element_region[candidates] == parts.contact_regions[c]]
        if not any(set(ids) <= set(nodes[e].tolist()) for e in candidates.tolist()):
            raise FormatError(f"{path}: member contact_face_nodes: face {k} of contact "
                              f"{shown(parts.contact_names[c])} is no face of an element of its region "
                              f"{shown(parts.names[parts.contact_regions[c]])}")



def _verify_interfaces(dual: Dual, sets: tuple[np.ndarray, ...], path: str | Path) -> None:
    """A version 5 file's interfaces computed again from its elements and their regions and compared exactly:
    the region pairs, the faces between elements of two regions (each oriented out of the lower region's
    element), each face's interface, and every (vertex, interface) area part."""
    from ...mesh.surfaces import interface_parts

    _, face, _, pair, pairs, which = sets
    parts = dual.regions
    given = parts.interfaces if parts is not None else None
    if parts is None or given is None:
        raise ValueError("_verify_interfaces: a dual without interfaces")
    try:
        a, b, c = (Fraction(text) for text in dual.box.texts)
    except ValueError:
        raise FormatError(f"{path}: manifest: a device's domain lengths must be rational") from None
    lengths = (a, b, c)
    again = interface_parts(dual.grid_vertices, dual.grid, lengths, parts.names, pairs, face[pair[:, 0]], which)
    if not np.array_equal(again.regions, given.regions):
        raise FormatError(f"{path}: manifest: interface_regions {given.regions.tolist()[:8]} are not the region pairs "
                          f"whose elements meet ({again.regions.tolist()[:8]})")
    ours, theirs = _oriented(again.face_nodes, again.face_interface), _oriented(given.face_nodes, given.face_interface)
    if ours.shape != theirs.shape or not np.array_equal(ours, theirs):
        raise FormatError(f"{path}: member interface_face_nodes: not the faces between elements of two regions, "
                          f"each oriented out of the lower region's ({len(theirs)} faces, its elements have "
                          f"{len(ours)})")
    if not (np.array_equal(again.vertex, given.vertex) and np.array_equal(again.interface, given.interface)):
        raise FormatError(f"{path}: member interface_part_vertex: not the rows its interface faces give "
                          f"({len(given.vertex)} rows, they give {len(again.vertex)})")
    wrong = np.flatnonzero(np.asarray(again.exact.astype(object) * given.denominator
                                      != given.exact.astype(object) * again.denominator).reshape(-1))
    if len(wrong):
        k = int(wrong[0])
        raise FormatError(f"{path}: member interface_part_exact: row {k} (vertex {int(given.vertex[k])}, interface "
                          f"{shown(given.names[given.interface[k]])}) is not the part its faces give")


def _oriented(faces: np.ndarray, which: np.ndarray) -> np.ndarray:
    """Polygons (-1 padded) each turned to start at its smallest vertex, orientation kept, with their set in the
    last column, rows sorted: equal for the same oriented faces in any order and from any first corner."""
    width = max(faces.shape[1] if faces.ndim == 2 else 0, 4)
    rows = []
    for polygon, w in zip(faces.tolist(), which.tolist()):
        ids = [v for v in polygon if v >= 0]
        k = ids.index(min(ids))
        rows.append(ids[k:] + ids[:k] + [-1] * (width - len(ids)) + [w])
    table = np.array(rows, dtype=np.int64).reshape(-1, width + 1)
    return table[np.lexsort(table.T[::-1])] if len(table) else table
