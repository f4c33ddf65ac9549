"""The pieces of a mesh, grouped: once per configuration (or element shape), with the members that share them.

The pieces of a leaf's configuration scale with the leaf's size (coefficients as
``h``, areas as ``h^2``, volumes as ``h^3``), so they are computed once per
configuration (and remembered across meshes; measured once per class of configurations
equal up to the box's symmetries, carried over to the others), once per shape of the cells that
replace leaves, or, for an element list given as such, once per distinct element
shape up to translation and powers of two.  Each :class:`Group` holds its pieces
(:class:`ShapePieces`, keyed by local node ids) and the rows of global vertex ids of
its members with their sizes: what :mod:`~cospherical.mesh.dual.sums` scatters.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import TYPE_CHECKING, Hashable, Mapping, NamedTuple, Sequence, TypeVar

import numpy as np
from numpy.typing import NDArray

from ...core.configuration import Box
from ...core.geometry import Frame, Rational
from ...core.polyhedron import measure
from ...core.symmetry import axis_maps
from ...errors import InputError
from .pieces import ElementPieces, Point, element_pieces

if TYPE_CHECKING:
    from ..assembly import LocalElement, LocalTessellation, Mesh

__all__ = ["Group", "ShapePieces", "cell_groups", "element_groups", "leaf_groups", "row_hashes"]

Squared = tuple[Fraction, Fraction, Fraction]


class ShapePieces:
    """The pieces of one element shape (or one configuration: its elements' pieces summed), keyed by local node ids.

    ``edges`` (k x 2, ``u < v``, sorted) with ``edge_numerators`` over ``edge_denominator`` their
    shares of ``area / length`` over ``a*b*c``; ``volume_nodes`` with ``volume_numerators`` over
    ``volume_denominator`` their control-volume shares over ``a*b*c``; ``boundary``: sorted
    ``((axis, plane value, node), numerator)`` over ``boundary_denominator``, the shares of the faces
    that lie in a coordinate plane (see :class:`~cospherical.mesh.dual.pieces.ElementPieces`).
    Each denominator is the least common one of its shares in lowest terms, so that the mesh's
    common denominators (:func:`~cospherical.mesh.dual.sums.mesh_dual`) are those of the fractions.
    """

    __slots__ = ("edges", "edge_numerators", "edge_denominator", "volume_nodes", "volume_numerators",
                 "volume_denominator", "boundary", "boundary_denominator")

    def __init__(self, edges: NDArray[np.int64], edge_numerators: list[int], edge_denominator: int,
                 volume_nodes: NDArray[np.int64], volume_numerators: list[int], volume_denominator: int,
                 boundary: list[tuple[tuple[int, Fraction, int], int]], boundary_denominator: int) -> None:
        self.edges = edges
        self.edge_numerators = edge_numerators
        self.edge_denominator = edge_denominator
        self.volume_nodes = volume_nodes
        self.volume_numerators = volume_numerators
        self.volume_denominator = volume_denominator
        self.boundary = boundary
        self.boundary_denominator = boundary_denominator

    @classmethod
    def summed(cls, pieces_list: Sequence[ElementPieces]) -> ShapePieces:
        """The pieces of elements that share their nodes' numbering (a configuration's), summed."""
        edges, edge_denominator = _summed([item for pieces in pieces_list for item in pieces.edges.items()])
        volumes, volume_denominator = _summed([item for pieces in pieces_list for item in pieces.volumes.items()])
        # a node lies in one plane normal to each axis: (axis, node) keys the plane's shares, its value beside
        planes = {(axis, node): value for pieces in pieces_list for (axis, value), shares in pieces.boundary.items()
                  for node in shares}
        boundary, boundary_denominator = _summed([((axis, node), q) for pieces in pieces_list
                                                  for (axis, _), shares in pieces.boundary.items()
                                                  for node, q in shares.items()])
        keys = sorted(edges)
        nodes = sorted(volumes)
        # sorted by (axis, plane, node), the planes compared as integers over their common denominator (the same
        # order as the fractions', at a fraction of the cost)
        entries = [((axis, planes[axis, node], node), n) for (axis, node), n in boundary.items()]
        common = math.lcm(1, *(value.denominator for (_, value, _), _ in entries))
        entries.sort(key=lambda entry: (entry[0][0], entry[0][1].numerator * (common // entry[0][1].denominator),
                                        entry[0][2]))
        return cls(np.array(keys, dtype=np.int64).reshape(-1, 2), [edges[k] for k in keys], edge_denominator,
                   np.array(nodes, dtype=np.int64), [volumes[n] for n in nodes], volume_denominator,
                   entries, boundary_denominator)

    def moved(self, node: Sequence[int], axis: Sequence[int], points: Mapping[int, tuple[int, int, int]],
              scale: int) -> ShapePieces:
        """These pieces carried over by an isometry of the box: node ``u`` becomes ``node[u]``, a plane normal to
        axis ``a`` one normal to ``axis[a]``, its value read from the moved nodes' points (``points[n] / scale``).
        The shares are the same numbers (lengths, areas, volumes and their signs are kept), in the new order."""
        # node ids mapped and sorted as arrays (the map is one to one: no two edges or nodes become equal, so the
        # order is that of the sorted pairs; the numerators follow it)
        ids = np.array(node, dtype=np.int64)
        ends = ids[self.edges]
        ends.sort(axis=1)
        edge_order = np.lexsort((ends[:, 1], ends[:, 0])).tolist()
        nodes = ids[self.volume_nodes]
        volume_order = np.argsort(nodes, kind="stable")
        # sorted by (axis, plane, node) as summed sorts them, every plane here being an integer over ``scale``
        moved = sorted((axis[a], points[node[u]][axis[a]], node[u], n) for (a, _, u), n in self.boundary)
        planes: dict[tuple[int, int], Fraction] = {}  # one Fraction per plane
        boundary = []
        for b, value, u, n in moved:
            plane = planes.get((b, value))
            if plane is None:
                plane = planes[b, value] = Fraction(value, scale)
            boundary.append(((b, plane, u), n))
        return ShapePieces(ends[edge_order], [self.edge_numerators[k] for k in edge_order], self.edge_denominator,
                           nodes[volume_order], [self.volume_numerators[k] for k in volume_order.tolist()],
                           self.volume_denominator, boundary, self.boundary_denominator)


Key = TypeVar("Key", bound=Hashable)


def _summed(items: Sequence[tuple[Key, Fraction]]) -> tuple[dict[Key, int], int]:
    """The fractions of each key summed, as integer numerators over their least common denominator in lowest
    terms: over the fractions' common denominator first (a sum of fractions one by one reduces every partial sum),
    then divided by what that denominator shares with every sum (the lcm of the sums' own denominators)."""
    common = math.lcm(1, *(q.denominator for _, q in items))
    totals: dict[Key, int] = {}
    for key, q in items:
        totals[key] = totals.get(key, 0) + q.numerator * (common // q.denominator)
    shared = math.gcd(common, *totals.values())
    return {key: total // shared for key, total in totals.items()}, common // shared


class Group(NamedTuple):
    """Members sharing one :class:`ShapePieces`: member ``i``'s node ``n`` is global vertex
    ``source[rows[i], n]``, and its pieces are scaled by ``sizes[i]`` (a power of two, grid units)."""

    pieces: ShapePieces
    source: NDArray[np.integer]
    rows: NDArray[np.int64]
    sizes: NDArray[np.int64]


def _real_centers(low: NDArray[np.int64], center: Sequence[Rational], size: NDArray[np.int64], lengths: NDArray[np.float64],
                  grid: int) -> NDArray[np.float64]:
    """Circumcenters as real coordinates: ``low`` corners (grid units) plus ``center`` (unit offsets) times ``size``."""
    result: NDArray[np.float64] = (low + np.array([float(x) for x in center]) * size) * (lengths / grid)
    return result


def leaf_groups(mesh: Mesh, squared: Squared) -> tuple[list[Group], NDArray[np.float64]]:
    """Per configuration: its pieces, the slots and its leaves (their rows of global vertex ids), their sizes;
    and the real circumcenter of every element (the cells' rows are left for :func:`cell_groups`)."""
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
        # every element of every leaf at once (leaves x elements x 3), by the sums and products of _real_centers
        # each coordinate n / d as float(Fraction) divides it (int / int, rounded once), without its four calls
        offsets = np.array([[n / d for n, d in (x.as_integer_ratio() for x in element.center)] for element in tessellation.elements
                            if element.center is not None]).reshape(1, -1, 3)
        # in place, one array of the group's size (low + offset * size == offset * size + low: sums commute, bit
        # for bit), its rows put in with a flat index (numpy's fast path)
        placed: NDArray[np.float64] = offsets * size[:, :, None]
        placed += low[:, None, :]
        placed *= lengths / mesh.grid
        centers[(first[:, None] + np.arange(offsets.shape[1])).reshape(-1)] = placed.reshape(-1, 3)
        groups.append(Group(_tessellation_pieces(tessellation, squared), mesh.slots, leaves, sizes[leaves]))
    return groups, centers


def cell_groups(mesh: Mesh, squared: Squared, centers: NDArray[np.float64]) -> list[Group]:
    """Per shape of the cells that replace leaves: its pieces (grid units, scale 1), its rows of the cells' vertex
    ids; fills the cells' rows of ``centers``."""
    cells = mesh.cells
    if cells is None:
        return []
    lengths = np.array(mesh.box.to_float())
    groups = []
    for s, shape in enumerate(cells.shapes):
        rows = np.flatnonzero(cells.shape == s)
        points: dict[int, Point] = {n: (Fraction(o[0]), Fraction(o[1]), Fraction(o[2]))
                                    for n, o in enumerate(shape.offsets)}
        pieces = ShapePieces.summed([element_pieces(points, shape.faces, shape.center, squared)])
        groups.append(Group(pieces, cells.nodes, rows, np.ones(len(rows), dtype=np.int64)))
        centers[mesh.leaf_elements + rows] = _real_centers(cells.anchor[rows], shape.center, np.ones(1, np.int64),
                                                           lengths, mesh.grid)
    return groups


_REMEMBERED: dict[tuple[str, Squared, tuple[tuple[int, ...], ...]], ShapePieces] = {}
# per class of configurations (equal tessellations up to the box's symmetries, see _configuration_class): the
# pieces of the first one met, its nodes in the class's order and the axis each of its axes goes to in the class
_CONFIGURATIONS: dict[Hashable, tuple[ShapePieces, tuple[int, ...], tuple[int, ...]]] = {}


def _tessellation_pieces(tessellation: LocalTessellation, squared: Squared) -> ShapePieces:
    """A configuration's pieces, remembered by its code, box and element node lists (meshes share them).

    Measured once per class of configurations up to the box's symmetries (the level-6 sphere tree's 95
    configurations are 8 classes: a hanging node on one edge of a leaf is one class whichever edge it is on),
    and carried over from the class's first configuration for the others."""
    key = (tessellation.code, squared, tuple(e.nodes for e in tessellation.elements))
    shape = _REMEMBERED.get(key)
    if shape is None:
        # (numerator, denominator) of each coordinate in one call (a Fraction's numerator and denominator are
        # properties: two calls), then every point over the common denominator
        ratios = {n: (x.as_integer_ratio(), y.as_integer_ratio(), z.as_integer_ratio())
                  for n, (x, y, z) in tessellation.configuration.nodes().items()}
        scale = math.lcm(*(d for p in ratios.values() for _, d in p))
        grid = {n: (x * (scale // dx), y * (scale // dy), z * (scale // dz))
                for n, ((x, dx), (y, dy), (z, dz)) in ratios.items()}
        elements = [e for e in tessellation.elements if e.center is not None]
        configuration_class, order, axes = _configuration_class(grid, scale, elements, squared)
        known = _CONFIGURATIONS.get(configuration_class)
        if known is None:
            shape = ShapePieces.summed([_placed_pieces(grid, scale, e.nodes, e.faces, e.center, squared)
                                        for e in elements if e.center is not None])
            _CONFIGURATIONS[configuration_class] = (shape, order, axes)
        else:
            pieces, first, first_axes = known
            node = [0] * (max(first) + 1)
            for u, v in zip(first, order):
                node[u] = v
            # axis a of the first configuration is the class's axis k with first_axes[k] == a, this one's axes[k]
            axis = [0, 0, 0]
            for k in range(3):
                axis[first_axes[k]] = axes[k]
            shape = pieces.moved(node, axis, grid, scale)
        _REMEMBERED[key] = shape
    return shape


def _configuration_class(grid: Mapping[int, tuple[int, int, int]], scale: int, elements: Sequence[LocalElement],
                         squared: Squared) -> tuple[Hashable, tuple[int, ...], tuple[int, ...]]:
    """A configuration's class up to the box's symmetries, with its tessellation: the class's key, the node ids in
    the class's order, and the axis of the configuration that each of the class's axes is taken from.

    Two configurations of one class are one moved by an isometry of the box, point for point in the orders
    returned, with the same elements (node sets) and the same faces (node sets): so the same pieces up to that
    map.  An element's centre need not be compared: it is the centre of the sphere through its points."""
    ids = list(grid)
    g, order_index, codes, base, _ = _canonical(np.array([grid[n] for n in ids], dtype=np.int64), squared)
    order = tuple(ids[i] for i in order_index)
    position = {n: i for i, n in enumerate(order)}
    structure = frozenset((frozenset([position[n] for n in e.nodes]),
                           frozenset([frozenset([position[n] for n in face]) for face in e.faces])) for e in elements)
    return (scale, base, codes, structure, squared), order, tuple(_isometries(squared)[0][g].tolist())


def _placed_pieces(grid: Mapping[int, tuple[int, int, int]], scale: int, nodes: Sequence[int],
                   faces: Sequence[Sequence[int]], center: Point, squared: Squared) -> ElementPieces:
    """:func:`~cospherical.mesh.dual.pieces.element_pieces` of one element of a configuration (its points
    ``grid[n] / scale``), measured once per shape up to translation and moved to where the element lies.

    The pieces are functions of differences of points, so an element's are those of its shape (its points and
    centre less their low corner, in its node order, with its faces) with the node ids put back and each boundary
    plane moved by the corner; exactly, as rationals.  Half of the elements of a table's configurations repeat a
    shape met in another (the level-6 sphere tree's 95 configurations: 723 elements, 363 shapes).
    """
    low = tuple(min(grid[n][k] for n in nodes) for k in range(3))
    index = {n: i for i, n in enumerate(nodes)}
    points = tuple((grid[n][0] - low[0], grid[n][1] - low[1], grid[n][2] - low[2]) for n in nodes)
    # the centre less the corner, as integers: (c * scale - low) / scale, over c's denominator times scale
    x, y, z = ((c.numerator * scale - low[k] * c.denominator, c.denominator) for k, c in enumerate(center))
    shape = _shape_pieces(points, scale, tuple(tuple(index[n] for n in face) for face in faces), (x, y, z), squared)
    edges = {}
    for (u, v), q in shape.edges.items():
        a, b = nodes[u], nodes[v]
        edges[(a, b) if a < b else (b, a)] = q
    return ElementPieces(edges, {nodes[u]: q for u, q in shape.volumes.items()},
                         {(axis, value + Fraction(low[axis], scale)): {nodes[u]: q for u, q in shares.items()}
                          for (axis, value), shares in shape.boundary.items()})


Offset = tuple[tuple[int, int], tuple[int, int], tuple[int, int]]
_SHAPES: dict[tuple[tuple[tuple[int, int, int], ...], int, tuple[tuple[int, ...], ...], Offset, Squared],
              ElementPieces] = {}
_MAX_SHAPES = 1 << 16  # element shapes remembered at most (a table's configurations have a few hundred)
# per class of shapes (equal up to the box's symmetries and translation, see _shape_class): the pieces of the
# first shape met, and its nodes in the class's order
_CLASSES: dict[Hashable, tuple[ElementPieces, tuple[int, ...]]] = {}


_ISOMETRIES: dict[tuple[bool, bool, bool], tuple[NDArray[np.int64], NDArray[np.int64]]] = {}


def _isometries(squared: Squared) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The box's symmetries (:func:`~cospherical.core.symmetry.axis_maps`: the reflections, and the
    permutations of axes of equal length) as arrays, symmetries x coordinates: the axis each coordinate is
    taken from, and its sign (a reflection as ``-x``: the shapes' classes are up to translation)."""
    equal = (squared[0] == squared[1], squared[1] == squared[2], squared[0] == squared[2])
    found = _ISOMETRIES.get(equal)
    if found is None:  # the symmetries depend on which lengths are equal only
        maps = axis_maps(squared)
        found = _ISOMETRIES[equal] = (np.array([perm for perm, _ in maps], dtype=np.int64),
                                      np.array([[-1 if f else 1 for f in flips] for _, flips in maps], dtype=np.int64))
    return found


def _canonical(coordinates: NDArray[np.int64], squared: Squared
               ) -> tuple[int, list[int], tuple[int, ...], int, list[int]]:
    """Points (non-negative integers, one a row) in the form shared by their images under the box's symmetries.

    Every symmetry's image of the points, moved to its low corner, is coded one integer a point and sorted; the
    least such list (compared as lists) is the canonical one.  Returns that symmetry's index (into
    :func:`_isometries`), the points' order in the list, the list, the base of the codes and the image's low
    corner (what the symmetry's image was moved by)."""
    axes, signs = _isometries(squared)
    images = coordinates[:, axes] * signs  # points x symmetries x 3
    low = images.min(axis=0)
    images -= low
    base = int(coordinates.max()) + 1  # every image's coordinates are below it (its extents, permuted)
    codes = images @ np.array([base * base, base, 1], dtype=np.int64)  # points x symmetries
    ordered = np.sort(codes, axis=0).T.tolist()
    g = min(range(len(ordered)), key=ordered.__getitem__)
    return g, np.argsort(codes[:, g]).tolist(), tuple(ordered[g]), base, low[g].tolist()


def _shape_class(points: tuple[tuple[int, int, int], ...], scale: int, faces: tuple[tuple[int, ...], ...],
                 center: Offset, squared: Squared) -> tuple[Hashable, tuple[int, ...]]:
    """An element shape's class up to the box's symmetries and translation, and its nodes in the class's order.

    The class is the points' canonical form (:func:`_canonical`) with the image's centre and its faces as sets
    of positions in that form's list: two shapes of one class are one shape moved by an isometry of the box,
    point for point in the orders returned, with the same faces and centre, so that their pieces are the same
    up to that map (exact, as rationals: lengths, areas and volumes are kept, and so the signs).
    """
    axes, signs = _isometries(squared)
    g, order_index, codes, base, low = _canonical(np.array(points, dtype=np.int64), squared)
    order = tuple(order_index)
    position = {n: i for i, n in enumerate(order)}
    common = math.lcm(*(d for _, d in center))
    # the centre n / (d * scale) as integers over common * scale, moved like the points (Python integers: on a
    # tiny or huge domain they pass int64)
    offset = [n * (common // d) for n, d in center]
    moved = tuple(sign * offset[axis] - common * corner
                  for axis, sign, corner in zip(axes[g].tolist(), signs[g].tolist(), low))
    shape_faces = tuple(sorted(tuple(sorted(position[n] for n in face)) for face in faces))
    key = (scale, base, codes, common, moved, shape_faces, squared)
    return key, order


def _mapped(pieces: ElementPieces, first: tuple[int, ...], order: tuple[int, ...],
            points: tuple[tuple[int, int, int], ...], scale: int) -> ElementPieces:
    """The pieces of a shape of one class from those of another (its nodes ``first`` and ``order`` in the class's
    order): node ids put in place of node ids, each boundary plane found again as the coordinate plane the
    mapped nodes of its faces lie in (one axis on which they agree: a face is no line)."""
    node = dict(zip(first, order))
    edges = {}
    for (u, v), q in pieces.edges.items():
        a, b = node[u], node[v]
        edges[(a, b) if a < b else (b, a)] = q
    boundary = {}
    for shares in pieces.boundary.values():
        moved = {node[u]: q for u, q in shares.items()}
        ids = list(moved)
        axis = next(k for k in range(3) if all(points[i][k] == points[ids[0]][k] for i in ids))
        boundary[(axis, Fraction(points[ids[0]][axis], scale))] = moved
    return ElementPieces(edges, {node[u]: q for u, q in pieces.volumes.items()}, boundary)


def _shape_pieces(points: tuple[tuple[int, int, int], ...], scale: int, faces: tuple[tuple[int, ...], ...],
                  center: Offset, squared: Squared) -> ElementPieces:
    """The pieces of an element shape: points ``points / scale``, nodes numbered in order, centre coordinates
    ``numerator / (denominator * scale)``; remembered (shared: never changed by a caller).  Measured once per
    class of shapes up to the box's symmetries (the level-6 sphere tree's 363 shapes are 19 classes), and
    mapped from the class's first shape for the others."""
    key = (points, scale, faces, center, squared)
    found = _SHAPES.get(key)
    if found is None:
        if len(_SHAPES) >= _MAX_SHAPES:
            _SHAPES.clear()
            _CLASSES.clear()
        shape_class, order = _shape_class(points, scale, faces, center, squared)
        known = _CLASSES.get(shape_class)
        if known is None:
            x, y, z = (Fraction(n, d * scale) for n, d in center)
            found = element_pieces({i: (Fraction(p[0], scale), Fraction(p[1], scale), Fraction(p[2], scale))
                                    for i, p in enumerate(points)}, faces, (x, y, z), squared)
            _CLASSES[shape_class] = (found, order)
        else:
            found = _mapped(known[0], known[1], order, points, scale)
        _SHAPES[key] = found
    return found


def _measured_pieces(key: NDArray[np.int64], squared: Squared, element: int) -> tuple[ShapePieces, Point]:
    """The pieces and centre of one element shape (its vertices' grid offsets, in its own order), measured exactly:
    faces from its hull, centre from the sphere through it; ``element`` names it when it has no dual."""
    points: dict[int, Point] = {n: (Fraction(int(p[0])), Fraction(int(p[1])), Fraction(int(p[2])))
                                for n, p in enumerate(key.tolist())}
    frame = Frame.build(points, squared)
    measured = measure(frame, range(len(points)))
    if not measured.cycles:
        raise InputError(f"element {element} is flat: it has no dual")
    if measured.sphere is None or measured.center is None:
        raise InputError(f"element {element} is not co-spherical: it has no dual")
    return ShapePieces.summed([element_pieces(points, measured.cycles, measured.center, squared)]), measured.center




def _odd_constants(count: int) -> NDArray[np.uint64]:
    """``count`` odd 64-bit multipliers, well mixed (SplitMix64's finaliser of 1, 2, ...): the row hash's, made
    without numpy.random (its import costs a mesh run 10-15 ms)."""
    with np.errstate(over="ignore"):
        x = np.arange(1, count + 1, dtype=np.uint64) * np.uint64(0x9E3779B97F4A7C15)
        x = (x ^ (x >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        x = (x ^ (x >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        mixed: NDArray[np.uint64] = (x ^ (x >> np.uint64(31))) | np.uint64(1)
    return mixed


_ROW_HASH = _odd_constants(3 * 64)


def row_hashes(rows: NDArray[np.integer]) -> NDArray[np.uint64]:
    """One integer per row of at most 192 integers (equal rows, equal hashes): to sort integers instead of rows,
    the rows' equality then proved by comparing them."""
    hashed: NDArray[np.uint64] = (rows.astype(np.uint64) * _ROW_HASH[:rows.shape[1]]).sum(axis=1, dtype=np.uint64)
    return hashed  # the products and sums wrap around: a hash


def _equal_rows(keys: NDArray[np.int64]) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Classes of equal rows: each class's first row, and each row's class.  The rows are hashed to one
    integer each (a sort of integers, not of rows) and the classes then proved by comparing every row with
    its class's first; a collision (never seen) falls back to sorting the rows themselves."""
    _, first, which = np.unique(row_hashes(keys), return_index=True, return_inverse=True)
    if not np.array_equal(keys[first][which.reshape(-1)], keys):
        _, first, which = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    return first, which.reshape(-1)


def element_groups(box: Box, grid: int, vertices: NDArray[np.integer], squared: Squared,
                   conn: NDArray[np.integer], element_sizes: NDArray[np.integer]
                   ) -> tuple[list[Group], NDArray[np.float64]]:
    """Per distinct element shape (up to translation and powers of two): its pieces, vertex ids, scalings;
    and the real circumcenter of every element.

    An element's shape is its vertices' offsets from its low corner, in its own vertex
    order, divided by its scale: the largest power of two dividing every offset (the
    lowest bit set in any of them).  The shapes are found with one sort per element
    size, and each is measured once, in the order of its first element (which an error
    names).
    """
    verts = np.asarray(vertices, dtype=np.int64)
    lengths = np.array(box.to_float())
    sizes = np.asarray(element_sizes, dtype=np.int64)
    centers = np.zeros((len(conn), 3))
    # per shape: its first element, the element size, the shape, its members (indices into that size's rows),
    # and that size's elements, vertex ids, low corners and scales
    found = []
    for size in np.unique(sizes).tolist():
        members = np.flatnonzero(sizes == size)
        ids = np.asarray(conn[members, :size], dtype=np.int64)
        coords = verts[ids]
        low = coords.min(axis=1)
        rel = (coords - low[:, None, :]).reshape(len(members), -1)
        bits = np.bitwise_or.reduce(rel, axis=1)
        scale = bits & -bits  # the largest power of two dividing every offset
        keys = rel // np.maximum(scale, 1)[:, None]
        first, which = _equal_rows(keys)
        # each shape's members, in element order
        by_shape = np.split(np.argsort(which, kind="stable"), np.cumsum(np.bincount(which))[:-1])
        for k in range(len(first)):
            found.append((int(members[first[k]]), size, keys[first[k]], by_shape[k], members, ids, low, scale))
    groups = []
    for element, size, shape, mine, members, ids, low, scale in sorted(found, key=lambda entry: entry[0]):
        pieces, center = _measured_pieces(shape.reshape(size, 3), squared, element)
        centers[members[mine]] = (low[mine] + np.array([float(x) for x in center]) * scale[mine, None]) * (
            lengths / grid)
        groups.append(Group(pieces, ids[mine], np.arange(len(mine)), scale[mine]))
    return groups, centers
