"""Assemble a global mesh from an octree: each leaf's true configuration, its elements, global vertices.

A leaf's points are the mesh vertices on its closed box.  In a 1-irregular tree
they sit on the leaf's 27 half-spacing slots (the nodes 0-26 of the shared
numbering): a corner always, an edge midpoint where a smaller leaf touches that
edge, a face centre where the face neighbour is refined, and never the body
centre (a leaf is not split).  So the vertex set is the set of all leaf corners,
on the integer grid of spacing half the finest leaf, and a leaf's configuration
is which of its slots are vertices: exact integer identity, no search by distance.

Each distinct configuration is looked up (or tessellated) once and measured once,
exactly, from the element node lists alone: faces are the convex hull of an
element's nodes, volumes and circumspheres integer determinants in the
configuration's frame (:class:`cospherical.core.geometry.Frame`).  The checks then
work on whole arrays of leaves that share a configuration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction
from functools import cached_property
from typing import TYPE_CHECKING, Any, Callable, Iterable, Iterator, NamedTuple

import numpy as np
from numpy.typing import NDArray

from ..catalogue import Catalogue, apply_catalogue_criterion, shipped_catalogue
from ..core.codes import mask_code, point_suffix
from ..core.configuration import Box, Configuration
from ..core.element_types import ElementType
from ..core.polyhedron import measure
from ..core.shapes import CORNERS, EDGES, FACES
from ..core.geometry import Frame, Sphere, in_closed_box
from ..core.tessellation import tessellate
from ..errors import InputError
from ..paper import paper_class
from .tree import Octree, distinct

if TYPE_CHECKING:  # a device's module is imported where a device is meshed
    from .device import Regions

__all__ = ["CellShape", "Cells", "ElementBlock", "LocalElement", "LocalTessellation", "Lookup", "MeasureCache", "Mesh",
           "MeshType", "NODE_OFFSETS",
           "PAPER_FINAL", "assemble", "distinct", "local_tessellation", "type_info", "vertex_keys"]

# Twice the unit coordinates of the 27 nodes (corners, edge midpoints, face centres, body).
NODE_OFFSETS = np.array(
    [[2 * x for x in c] for c in CORNERS]
    + [[CORNERS[p][a] + CORNERS[q][a] for a in range(3)] for p, q in EDGES]
    + [[sum(CORNERS[n][a] for n in face) // 2 for a in range(3)] for face in FACES]
    + [[1, 1, 1]], dtype=np.int64)
PAPER_FINAL = ("Cuboid", "Triangular Prism", "Quadrilateral Pyramid", "Tetrahedron", "Tetrahedron Complement",
               "Deformed Prism", "Deformed Tetrahedron Complement")

# lookup(configuration) -> the table's elements (dicts with ``type`` and ``nodes``, and ``mapped_from``
# when they were carried back from another configuration of the orbit), or None when it lacks them
Lookup = Callable[[Configuration], "list[dict[str, Any]] | None"]


@dataclass(frozen=True)
class LocalElement:
    """One element of a configuration, measured exactly from its node list.

    ``faces``: node-id cycles counter-clockwise seen from outside (the hull of the
    nodes); ``unit_volume``: its share of the leaf; ``sphere``: the circumsphere in the
    configuration's frame, or ``None`` when the nodes are not all on one sphere;
    ``center``: its centre in unit coordinates of the leaf.
    """

    type_id: str
    nodes: tuple[int, ...]
    faces: tuple[tuple[int, ...], ...]
    unit_volume: Fraction
    sphere: Sphere | None
    center: tuple[Fraction, Fraction, Fraction] | None

    @cached_property  # read per element by several checks and writers: made once
    def center_in_leaf(self) -> bool:
        # 0 <= n/d <= 1 as 0 <= n <= d (a Fraction's denominator is positive): integers, not Fraction comparisons
        return self.center is not None and all(0 <= x.numerator <= x.denominator for x in self.center)

    @cached_property  # every walk over the mesh's blocks reads them: made once per element of a configuration
    def face_columns(self) -> tuple[tuple[int, ...], ...]:
        """:attr:`faces` as cycles of indices into :attr:`nodes` (the columns of a block's vertex ids)."""
        column = {n: i for i, n in enumerate(self.nodes)}
        return tuple(tuple(column[n] for n in cycle) for cycle in self.faces)


@dataclass(frozen=True)
class LocalTessellation:
    """A leaf's elements in its local node numbering (0..26), measured exactly, with the frame they were measured in.

    One per configuration that occurs in a mesh, shared by the leaves that have it; the
    elements come from a pattern table (the product) or are tessellated on the fly.
    """

    code: str
    configuration: Configuration
    elements: tuple[LocalElement, ...]
    scale: int
    weights: tuple[int, int, int]
    on_the_fly: bool
    mapped_from: str | None = None  # the table's orbit representative its elements were carried back from

    @cached_property
    def fvm_adequate(self) -> bool:
        """Every circumcenter in the closed leaf, decided exactly."""
        return all(e.center_in_leaf for e in self.elements)


# An element measured in a configuration's frame, by what the measure reads: the frame's scale and
# weights, the element's node ids in its order, and their frame coordinates.  The hull's cycles (in
# node ids), the volume, the sphere and its centre are functions of these alone (the hull reads the
# nodes' order and their coordinates; frame indices rank as node ids do), so configurations that share
# an element at the same points measure it once.
MeasureCache = dict[tuple[int, tuple[int, int, int], tuple[int, ...], tuple[tuple[int, int, int], ...]],
                    tuple[tuple[tuple[int, ...], ...], Fraction, Sphere | None,
                          tuple[Fraction, Fraction, Fraction] | None]]


def local_tessellation(configuration: Configuration, elements: Iterable[tuple[str, Iterable[int]]],
                       on_the_fly: bool = False, mapped_from: str | None = None,
                       measured: MeasureCache | None = None) -> LocalTessellation:
    """Measure a configuration's elements (type id, node ids) exactly, trusting nothing but the node lists.

    ``measured``: elements measured before, in other configurations of the same mesh (see
    :data:`MeasureCache`), taken as they are where their node ids and coordinates are the same.

    Examples
    --------
    >>> tessellation = local_tessellation(Configuration.from_code("000000000000", faces=[]),
    ...                               [("v8f6-c3cb81", range(8))])
    >>> element = tessellation.elements[0]
    >>> element.unit_volume, element.center, len(element.faces)
    (Fraction(1, 1), (Fraction(1, 2), Fraction(1, 2), Fraction(1, 2)), 6)
    """
    nodes = configuration.nodes()
    frame = Frame.build(nodes, configuration.box.squared)
    index = {node: i for i, node in enumerate(frame.ids)}
    cache: MeasureCache = {} if measured is None else measured
    elements_measured = []
    for type_id, element_nodes in elements:
        element_nodes = tuple(int(n) for n in element_nodes)
        missing = [n for n in element_nodes if n not in index]
        if missing:
            raise InputError(f"pattern table: configuration {configuration.code}: an element ({type_id}) uses "
                             f"node {missing[0]}, which the leaf does not have")
        members = [index[n] for n in element_nodes]
        key = (frame.scale, frame.weights, element_nodes, tuple(frame.coords[i] for i in members))
        found = cache.get(key)
        if found is None:
            # a flat element has no faces and no volume (the volume check reports it); one not co-spherical
            # has no sphere (it is not a Delaunay element)
            element = measure(frame, members)
            found = cache[key] = (tuple(tuple(frame.ids[i] for i in c) for c in element.cycles),
                                  element.unit_volume, element.sphere, element.center)
        elements_measured.append(LocalElement(type_id, element_nodes, *found))
    return LocalTessellation(configuration.point_set_code or "", configuration, tuple(elements_measured),
                             frame.scale, frame.weights, on_the_fly, mapped_from)


@dataclass(frozen=True)
class CellShape:
    """A Delaunay cell up to translation, measured exactly on the vertex grid.

    Cells of the global Delaunay subdivision are not leaf elements: they are kept
    once per shape (most are translates of a few), in grid units of the mesh.
    ``offsets``: the vertices relative to the cell's anchor (its lowest vertex id),
    in the type's reference order; ``faces``: cycles of indices into ``offsets``,
    counter-clockwise seen from outside; ``grid_volume``: its volume in grid cells;
    ``sphere``: its circumsphere in the frame of the offsets (integer coordinates,
    the box's squared lengths as weights); ``center``: the circumcenter's offset
    from the anchor in grid units, exact.
    """

    type_id: str
    offsets: tuple[tuple[int, int, int], ...]
    faces: tuple[tuple[int, ...], ...]
    grid_volume: Fraction
    sphere: Sphere
    center: tuple[Fraction, Fraction, Fraction]


@dataclass(frozen=True)
class Cells:
    """Cells that replace the elements of whole leaves (see :mod:`cospherical.mesh.delaunay`).

    Cell ``i`` has shape ``shapes[shape[i]]``, its anchor at grid point ``anchor[i]``
    and its vertices ``nodes[i, :len(offsets)]`` (global ids, -1 padded) in the
    shape's order.  ``leaf[i]`` is the cell's first leaf: the leaf whose box holds
    an interior point of it (the centroid of its vertices); ``spanning[i]``
    whether the cell reaches beyond that leaf; ``proven[i]`` whether it is a leaf
    element that passed the exact global check, kept as it is (the others were
    re-tessellated).  ``clusters`` (connected groups of leaf elements re-tessellated
    together; not a device's regions) and ``largest_cluster`` (in vertices) describe
    what was re-tessellated.
    """

    shapes: list[CellShape]
    shape: NDArray[np.integer[Any]]
    anchor: NDArray[np.int64]
    nodes: NDArray[np.integer[Any]]
    leaf: NDArray[np.integer[Any]]
    spanning: NDArray[np.bool_]
    proven: NDArray[np.bool_]
    clusters: int = 0
    largest_cluster: int = 0

    def __len__(self) -> int:
        return len(self.shape)


class ElementBlock(NamedTuple):
    """Elements of one kind (:meth:`Mesh.blocks`): one element of a configuration over its leaves, or a cell shape.

    ``rows``: the elements' indices in the mesh; ``nodes``: their global vertex ids (elements x
    nodes, in the type's node order); ``faces``: cycles of column indices into ``nodes``,
    counter-clockwise seen from outside; ``type_id``: the element type (``None`` for elements known
    only by their vertices: :func:`~cospherical.mesh.tetrahedra.element_blocks`).
    """

    rows: NDArray[np.int64]
    nodes: NDArray[np.integer[Any]]
    faces: tuple[tuple[int, ...], ...]
    type_id: str | None


@dataclass
class Mesh:
    """A global mesh assembled from an octree, as arrays.

    Vertices are integer points of the grid of spacing half the finest leaf
    (``grid`` intervals per domain side): ``vertices`` (n x 3).  Leaf ``i`` has
    configuration ``tessellations[leaf_tessellation[i]]`` and its node ``s`` (0..26) at vertex
    ``slots[i, s]`` (-1: no point there).  Elements are listed leaf by leaf, in each
    leaf in its tessellation's order: element ``e`` is element ``element_local[e]`` of
    leaf ``element_leaf[e]``; ``element_offsets[i]`` is the first element of leaf ``i``.
    Leaves marked in ``replaced`` contribute no elements: their part of the domain
    is tiled by ``cells``, listed after every leaf element (``element_local`` -1,
    ``element_leaf`` the cell's first leaf).  ``regions``: which region each leaf lies in
    (a device); ``None`` for a one-box domain.
    """

    tree: Octree
    grid: int
    vertices: NDArray[np.int64]
    slots: NDArray[np.int32]
    leaf_tessellation: NDArray[np.int32]
    tessellations: list[LocalTessellation]
    element_offsets: NDArray[np.int64]
    element_leaf: NDArray[np.int32]
    element_local: NDArray[np.int16]
    types: dict[str, MeshType] = field(default_factory=dict)
    replaced: NDArray[np.bool_] | None = None
    cells: Cells | None = None
    # names the types (assemble's catalogue; the shipped one when none is given)
    catalogue: Catalogue = field(default_factory=shipped_catalogue, repr=False, compare=False)
    regions: Regions | None = field(default=None, repr=False, compare=False)  # a device's regions
    # the leaves of each tessellation: all of them, and those whose elements are in the mesh (groups())
    _groups: tuple[list[NDArray[np.intp]], list[NDArray[np.intp]]] | None = field(default=None, repr=False,
                                                                                   compare=False)

    @property
    def box(self) -> Box:
        return self.tree.box

    def __len__(self) -> int:
        return len(self.element_leaf)

    def points(self) -> NDArray[np.float64]:
        """(n, 3) float64: the vertices in the domain's units, the root box's corner at 0.

        The one conversion from the exact grid (``vertices / grid`` of each side) to
        floats, so every writer and check places a vertex at the same float.
        """
        return self.vertices * (np.array(self.box.to_float()) / self.grid)

    @property
    def element_region(self) -> NDArray[np.integer[Any]] | None:
        """Per element, the index of its region (its leaf's; a cell's first leaf's), or ``None`` without regions."""
        return None if self.regions is None else self.regions.leaf_region[self.element_leaf]

    @property
    def domain_share(self) -> Fraction:
        """The domain's volume as a fraction of the root box's (1 but for a device whose boxes leave holes)."""
        layout = self.regions.layout if self.regions is not None else None
        if layout is None:
            return Fraction(1)
        lengths = [high - low for low, high in layout.device.bounds]
        return sum(layout.region_volumes, Fraction(0)) / (lengths[0] * lengths[1] * lengths[2])

    @property
    def leaf_elements(self) -> int:
        """How many elements come from the leaves' tessellations (the cells follow them)."""
        return len(self) - (len(self.cells) if self.cells is not None else 0)

    def leaf_size(self) -> NDArray[np.int64]:
        """Leaf edge lengths in grid units."""
        return (self.grid >> self.tree.levels.astype(np.int64)).astype(np.int64)

    def groups(self, all_leaves: bool = False) -> Iterator[tuple[int, LocalTessellation, NDArray[np.intp]]]:
        """Yield ``(tessellation index, tessellation, leaf indices)`` for every configuration that occurs, in order.

        The leaves are those whose elements are in the mesh; ``all_leaves`` also
        yields the replaced ones (for counting configurations).
        """
        if self._groups is None:  # every check walks the groups: sort the leaves once
            order = np.argsort(self.leaf_tessellation, kind="stable")
            counts = np.bincount(self.leaf_tessellation, minlength=len(self.tessellations))
            starts = np.r_[0, np.cumsum(counts)]
            groups = [order[starts[p]:starts[p + 1]] for p in range(len(self.tessellations))]
            kept = groups if self.replaced is None else [g[~self.replaced[g]] for g in groups]
            self._groups = (groups, kept)
        for p, leaves in enumerate(self._groups[0 if all_leaves else 1]):
            if len(leaves) or all_leaves:
                yield p, self.tessellations[p], leaves

    def blocks(self, near: NDArray[np.bool_] | None = None) -> Iterator[ElementBlock]:
        """Yield ``(element indices, global vertex ids (elements x nodes), faces, type id)`` per kind of element.

        One block per element of a configuration (over its leaves) and per cell
        shape; ``faces`` are cycles of column indices into the vertex ids.  ``near``
        (a mask over the leaves): only the leaf elements of those leaves (every cell).
        """
        for _, tessellation, leaves in self.groups():
            if near is not None:
                leaves = leaves[near[leaves]]
                if not len(leaves):
                    continue
            first = self.element_offsets[leaves]
            slots = self.slots[leaves]  # the configuration's slots once, each element's columns from it
            for j, element in enumerate(tessellation.elements):
                yield ElementBlock(first + j, slots[:, np.asarray(element.nodes, dtype=np.intp)], element.face_columns,
                                   element.type_id)
        yield from self._cell_blocks()

    def _cell_blocks(self) -> Iterator[ElementBlock]:
        """:meth:`blocks` of the cells that replace leaves: one per cell shape (none without cells)."""
        if self.cells is not None:
            order = np.argsort(self.cells.shape, kind="stable")
            counts = np.bincount(self.cells.shape, minlength=len(self.cells.shapes))
            starts = np.r_[0, np.cumsum(counts)]
            for s, shape in enumerate(self.cells.shapes):
                rows = order[starts[s]:starts[s + 1]]
                yield ElementBlock(self.leaf_elements + rows, self.cells.nodes[rows, :len(shape.offsets)],
                                   shape.faces, shape.type_id)

    def block_types(self) -> Iterator[tuple[NDArray[np.int64], str]]:
        """:meth:`blocks`' element indices and type ids alone (no vertex ids gathered)."""
        for _, tessellation, leaves in self.groups():
            first = self.element_offsets[leaves]
            for j, element in enumerate(tessellation.elements):
                yield first + j, element.type_id
        if self.cells is not None:
            order = np.argsort(self.cells.shape, kind="stable")
            counts = np.bincount(self.cells.shape, minlength=len(self.cells.shapes))
            starts = np.r_[0, np.cumsum(counts)]
            for s, shape in enumerate(self.cells.shapes):
                yield self.leaf_elements + order[starts[s]:starts[s + 1]], shape.type_id

    def element_nodes(self, elements: NDArray[np.integer[Any]]) -> NDArray[np.int32]:
        """Global vertex ids of the given leaf elements, in their tessellation's node order, padded with -1."""
        width = max((len(e.nodes) for p in self.tessellations for e in p.elements), default=1)
        widest = max((len(p.elements) for p in self.tessellations), default=1)
        # (tessellation, element) -> local nodes, padded with slot 26 (the body centre: never a vertex, so -1)
        local = np.full((len(self.tessellations), widest, width), 26, dtype=np.int64)
        for p, tessellation in enumerate(self.tessellations):
            for j, element in enumerate(tessellation.elements):
                local[p, j, :len(element.nodes)] = element.nodes
        leaf = self.element_leaf[elements]
        nodes: NDArray[np.int32] = self.slots[leaf[:, None], local[self.leaf_tessellation[leaf],
                                                                  self.element_local[elements]]]
        return nodes

    def connectivity(self) -> tuple[NDArray[np.int32], NDArray[np.int8]]:
        """Global vertex ids of every element: (elements x widest) int32 padded with -1, and the sizes.

        The leaf elements one configuration at a time (all its elements of all its leaves in one gather,
        each element's nodes padded with slot 26, the body centre, never a vertex: -1), not one block an
        element: the same arrays as :meth:`blocks` gives, in a fifth of the time at level 6."""
        groups = list(self.groups())
        cells = [(rows, nodes) for rows, nodes, _, _ in self._cell_blocks()]
        width = max([len(element.nodes) for _, tessellation, _ in groups for element in tessellation.elements]
                    + [nodes.shape[1] for _, nodes in cells], default=0)
        conn = np.full((len(self), width), -1, dtype=np.int32)
        sizes = np.zeros(len(self), dtype=np.int8)
        for _, tessellation, leaves in groups:
            count = len(tessellation.elements)
            local = np.full((count, width), 26, dtype=np.intp)
            for j, element in enumerate(tessellation.elements):
                local[j, :len(element.nodes)] = element.nodes
            rows = (self.element_offsets[leaves][:, None] + np.arange(count)).reshape(-1)
            conn[rows] = self.slots[leaves][:, local.reshape(-1)].reshape(-1, width)
            sizes[rows] = np.tile(np.array([len(element.nodes) for element in tessellation.elements]), len(leaves))
        for rows, nodes in cells:
            conn[rows, :nodes.shape[1]] = nodes
            sizes[rows] = nodes.shape[1]
        return conn, sizes

    def element_types(self) -> tuple[list[str], NDArray[np.int32]]:
        """The type ids met (sorted) and each element's index into them."""
        blocks = list(self.block_types())
        ids = sorted({type_id for _, type_id in blocks})
        position = {t: i for i, t in enumerate(ids)}
        codes = np.zeros(len(self), dtype=np.int32)
        for rows, type_id in blocks:
            codes[rows] = position[type_id]
        return ids, codes

    def element_fvm(self) -> NDArray[np.bool_]:
        """Per element: its circumcenter lies in its closed leaf (exact; a cell's leaf is its first leaf)."""
        flags = np.zeros(len(self), dtype=bool)
        for _, tessellation, leaves in self.groups():
            first = self.element_offsets[leaves]
            for j, element in enumerate(tessellation.elements):
                flags[first + j] = element.center_in_leaf
        if self.cells is not None:
            flags[self.leaf_elements:] = self.cell_center_in_leaf()
        return flags

    def type_name(self, type_id: str) -> str:
        """The name of one of the mesh's types (its id when :attr:`types` does not hold it)."""
        info = self.types.get(type_id)
        return info.name if info is not None else type_id

    def type_vtk(self, type_id: str) -> str | None:
        """The standard VTK cell one of the mesh's types is written as (``None``: a polyhedron, or not known)."""
        info = self.types.get(type_id)
        return info.vtk if info is not None else None

    def required_cells(self) -> Cells:
        """The cells, for what only a mesh with re-tessellated cells has (a ``ValueError`` without them)."""
        if self.cells is None:
            raise ValueError("the mesh has no re-tessellated cells")
        return self.cells

    def cell_centers(self) -> tuple[NDArray[Any], NDArray[Any]]:
        """The cells' circumcenters in grid units, exact: numerators (cells x 3) and denominators.

        int64 when the numerators and what the checks compare them with (grid points up
        to twice the grid times a denominator) stay below 2**62, else Python integers.
        """
        cells = self.required_cells()
        parts = []
        for shape in cells.shapes:
            common = math.lcm(*(c.denominator for c in shape.center))
            parts.append((common, [c.numerator * (common // c.denominator) for c in shape.center]))
        bound = max((2 * self.grid * common + max(map(abs, p)) for common, p in parts), default=0)
        kind = np.int64 if bound < 2**62 else object
        num = np.empty((len(cells), 3), dtype=kind)
        den = np.empty(len(cells), dtype=kind)
        order = np.argsort(cells.shape, kind="stable")
        starts = np.searchsorted(cells.shape[order], np.arange(len(parts) + 1))
        for s, (common, p) in enumerate(parts):
            rows = order[starts[s]:starts[s + 1]]
            num[rows] = cells.anchor[rows].astype(kind) * common + np.array(p, dtype=kind)[None]
            den[rows] = common
        return num, den

    def cell_center_in_leaf(self) -> NDArray[np.bool_]:
        """Per cell: its circumcenter lies in the closed box of its first leaf, decided exactly."""
        num, den = self.cell_centers()
        leaf = self.required_cells().leaf
        size = self.leaf_size()[leaf].astype(num.dtype)
        low = self.tree.positions[leaf].astype(num.dtype) * size[:, None]
        return in_closed_box(num, den[:, None], low, low + size[:, None]).astype(bool)

@dataclass(frozen=True)
class MeshType:
    """What an element type of a mesh is, as its files and its report name it.

    Attributes
    ----------
    name : str
        The catalogue's name of the type, else its systematic name (else its id).
    paper_class : str or None
        The paper's class of the type, if it has one.
    vtk : str or None
        The standard VTK cell it is written as (``None``: a polyhedron).
    vertices, faces : int or None
        Its vertices and faces (``None`` when known by its id alone).
    """

    name: str
    paper_class: str | None
    vtk: str | None
    vertices: int | None
    faces: int | None


def type_info(type_id: str, etype: ElementType | None, catalogue: Catalogue) -> MeshType:
    """Name, paper class, VTK cell and size of a type: from the catalogue, else from the type itself."""
    entry = catalogue.get(type_id)
    if entry is not None:
        return MeshType(entry.name, entry.paper_class, entry.vtk, entry.vertices, entry.faces)
    if etype is not None:
        cls = paper_class(etype)
        return MeshType(etype.name, cls["name"] if cls else None, etype.vtk, etype.vertices, etype.faces)
    return MeshType(type_id, None, None, None, None)


def _leaf_code(edges: int, faces: int) -> str:
    """The whole-point-set code of a leaf from its edge and face bit masks.

    >>> _leaf_code(0b1, 0), _leaf_code(0xfff, 0b010001)
    ('800000000000+f', '888888888888+f04')
    """
    return mask_code(edges, 12) + "+" + point_suffix((f for f in range(6) if faces >> f & 1), False)


def vertex_keys(tree: Octree) -> tuple[int, NDArray[np.int64]]:
    """The vertex grid of a tree: its intervals per domain side and the sorted keys of every leaf corner.

    A vertex ``(x, y, z)`` of the grid has the key ``(x * (grid + 1) + y) * (grid + 1) + z``;
    its index in the keys is its id in the mesh, so a mesh assembled from a part of the
    tree with these keys numbers its vertices as the whole tree's mesh does.
    """
    grid, origin, half = _leaf_boxes(tree)
    return grid, distinct(_node_keys(origin, half, grid, _CORNERS), runs=True)


_CORNERS = np.arange(8)


def _leaf_boxes(tree: Octree, grid: int | None = None) -> tuple[int, NDArray[np.int64], NDArray[np.int64]]:
    """The grid (intervals per domain side: the tree's own unless given), and each leaf's lowest corner and half
    its side in grid units."""
    grid = 1 << (tree.depth + 1) if grid is None else grid
    size = grid >> tree.levels.astype(np.int64)
    return grid, tree.positions.astype(np.int64) * size[:, None], size // 2


def _node_keys(origin: NDArray[np.int64], half: NDArray[np.int64], grid: int,
               nodes: NDArray[np.int64]) -> NDArray[np.int64]:
    """The keys of the leaves' ``nodes`` (node numbers 0..26), node by node: (nodes x leaves).

    A point's key (x * n + y) * n + z is linear in the point: a node's key is its leaf origin's key plus
    half the leaf times the key of the node's offset.  Leaves in key order (within a level) make
    increasing runs, one per node and level.
    """
    n = np.int64(grid + 1)
    offsets = NODE_OFFSETS[nodes]
    keys: NDArray[np.int64] = ((offsets[:, 0] * n + offsets[:, 1]) * n + offsets[:, 2])[:, None] * half[None]
    keys += ((origin[:, 0] * n + origin[:, 1]) * n + origin[:, 2])[None]
    return keys


def _leaf_slots(tree: Octree, vertices: tuple[int, NDArray[np.int64]] | None = None
               ) -> tuple[int, NDArray[np.int64], NDArray[np.int32]]:
    """The tree's grid, vertex keys (:func:`vertex_keys`, or ``vertices`` when given) and each leaf's 27 slots.

    ``slots[i, s]`` is the id of the vertex at node ``s`` of leaf ``i`` (its index in the
    keys), -1 where there is none.  Every key asked for (each leaf's corners; the other
    nodes of the leaves above the finest grid level) and the vertex keys are sorted together
    once, stably: they are a few increasing runs (one per node and level), which timsort
    merges; a key is a vertex where its run of equal keys holds a vertex key (a leaf corner,
    or one of ``vertices``), and its id is that run's rank among such runs.  A leaf of the
    grid's finest level (two grid steps a side) has no point at its edges' and faces'
    midpoints or its centre: every vertex is a leaf corner, at even grid coordinates, and
    those nodes are at odd ones.  The finest level is the grid's, not the tree's: a part of a
    tree (a partition piece, a device's region) may stop levels above the whole.
    """
    grid, origin, half = _leaf_boxes(tree, None if vertices is None else vertices[0])
    coarse = np.flatnonzero(half > 1)
    given = vertices[1] if vertices is not None else np.zeros(0, dtype=np.int64)
    # every key asked for in one array (int32 while the grid's keys fit: half the bytes to sort)
    kind = np.int32 if (grid + 1) ** 3 < 2**31 else np.int64
    corners = slice(len(given), len(given) + 8 * len(tree))
    asked = np.empty(corners.stop + len(_OTHERS) * len(coarse), dtype=kind)
    asked[:corners.start] = given
    asked[corners] = _node_keys(origin, half, grid, _CORNERS).reshape(-1)
    asked[corners.stop:] = _node_keys(origin[coarse], half[coarse], grid, _OTHERS).reshape(-1)
    order = np.argsort(asked, kind="stable")
    ordered = asked[order]
    del asked
    first = np.empty(len(ordered), dtype=bool)
    first[:1] = True
    np.not_equal(ordered[1:], ordered[:-1], out=first[1:])
    run = np.cumsum(first, dtype=np.int32)
    run -= 1
    keys = ordered[first]
    del ordered, first
    # the runs that hold a vertex key: a given one, else a corner
    is_vertex = np.zeros(len(keys), dtype=bool)
    is_vertex[run[order < (corners.start if vertices is not None else corners.stop)]] = True
    ids = np.where(is_vertex, np.cumsum(is_vertex, dtype=np.int32) - 1, -1).astype(np.int32)
    found = np.empty(len(order), dtype=np.int32)
    found[order] = ids[run]
    del order, run
    slots = np.full((len(tree), 27), -1, dtype=np.int32)
    slots[:, :8] = found[corners].reshape(8, -1).T
    slots[coarse, 8:] = found[corners.stop:].reshape(len(_OTHERS), -1).T
    return grid, given if vertices is not None else keys[is_vertex].astype(np.int64), slots


_OTHERS = np.arange(8, 27)


def assemble(tree: Octree, lookup: Lookup | None = None, progress: Callable[[int], None] | None = None,
             cache: dict[tuple[str, str], LocalTessellation] | None = None, criterion: str = "optimal",
             vertices: tuple[int, NDArray[np.int64]] | None = None, catalogue: Catalogue | None = None) -> Mesh:
    """Mesh an octree: configurations from the vertex set, elements from ``lookup`` (else tessellated).

    ``lookup(configuration)`` returns the pattern table's elements of that point set
    (dicts with ``type`` and ``nodes``) or ``None`` when the table lacks it; a
    configuration without table elements is tessellated on the fly (and marked so), its
    elements split by the catalogue's kept types when ``criterion`` is not ``optimal``.
    ``cache`` ((code, criterion) -> :class:`LocalTessellation`) may be shared between runs.
    ``progress(n)`` is told as leaves are assembled.  ``vertices``: the grid and vertex keys
    (:func:`vertex_keys`) of a whole tree of which ``tree`` is a part: the part's
    configurations and vertex ids are then the whole tree's.  ``catalogue``: the element
    catalogue that names the types and gives the kept types of ``criterion`` (default: the
    shipped one); the mesh keeps it (:attr:`Mesh.catalogue`) for its report.

    Examples
    --------
    >>> from cospherical.mesh.octree import build_octree, parse_shape
    >>> mesh = assemble(build_octree(Box.parse([1, 1, 1]), 1, [parse_shape("point:0.5,0.5,0.5")]))
    >>> len(mesh.tree), len(mesh.vertices), len(mesh)
    (8, 27, 8)
    """
    cache = {} if cache is None else cache
    catalogue = shipped_catalogue() if catalogue is None else catalogue
    grid, keys_all, slots = _leaf_slots(tree, vertices)
    n = np.int64(grid + 1)
    points = np.stack([keys_all // (n * n), (keys_all // n) % n, keys_all % n], axis=1)
    if progress:
        progress(len(tree) // 2)
    if (slots[:, 26] >= 0).any():
        i = int(np.flatnonzero(slots[:, 26] >= 0)[0])
        raise InputError(f"leaf {i}: a vertex at its centre: the leaves do not form an octree")
    # bit k: a point at edge k's midpoint (node 8 + k), bit 12 + f: at face f's centre (node 20 + f)
    value = (slots[:, 8:26] >= 0).astype(np.int32) @ (np.int32(1) << np.arange(18, dtype=np.int32))
    seen = np.bincount(value, minlength=1 << 18) > 0  # < 2**18: count instead of sorting
    distinct = np.flatnonzero(seen)
    leaf_tessellation = (np.cumsum(seen) - 1)[value]
    tessellations: list[LocalTessellation] = []
    types: dict[str, MeshType] = {}
    measured: MeasureCache = {}
    for value in distinct.tolist():
        code = _leaf_code(value & 0xFFF, value >> 12)
        if (code, criterion) not in cache:
            cache[code, criterion] = _leaf_tessellation(Configuration.from_code(code, tree.box), lookup, types,
                                                        criterion, catalogue, measured)
        tessellations.append(cache[code, criterion])
    for tessellation in tessellations:
        for element in tessellation.elements:
            if element.type_id not in types:
                types[element.type_id] = type_info(element.type_id, None, catalogue)
    counts = np.array([len(p.elements) for p in tessellations], dtype=np.int64)[leaf_tessellation]
    offsets = np.zeros(len(tree) + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    element_leaf = np.repeat(np.arange(len(tree), dtype=np.int32), counts)
    element_local = (np.arange(offsets[-1], dtype=np.int64) - offsets[:-1][element_leaf]).astype(np.int16)
    if progress:
        progress(len(tree) - len(tree) // 2)
    return Mesh(tree, grid, points, slots, leaf_tessellation.astype(np.int32).reshape(-1), tessellations, offsets,
                element_leaf, element_local, types, catalogue=catalogue)


def _leaf_tessellation(configuration: Configuration, lookup: Lookup | None, types: dict[str, MeshType],
                       criterion: str, catalogue: Catalogue, measured: MeasureCache) -> LocalTessellation:
    elements = lookup(configuration) if lookup is not None else None
    if elements is not None:
        return local_tessellation(configuration, [(e["type"], e["nodes"]) for e in elements],
                                  mapped_from=next((e["mapped_from"] for e in elements if "mapped_from" in e), None),
                                  measured=measured)
    tess = apply_catalogue_criterion(tessellate(configuration), criterion, catalogue)
    for element in tess.elements:
        types.setdefault(element.type.id, type_info(element.type.id, element.type, catalogue))
    return local_tessellation(configuration, [(e.type.id, e.nodes) for e in tess.elements], on_the_fly=True,
                              measured=measured)
