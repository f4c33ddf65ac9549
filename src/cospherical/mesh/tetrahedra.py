"""Split a mesh of co-spherical elements into tetrahedra, without new vertices, conforming.

Most solvers read only simplices.  Every element is convex and its faces are
convex polygons (points of one circle), so an element is the union of the cones
from one of its vertices (the *apex*) over the faces that do not contain it, each
face fanned into triangles from one of its vertices::

        apex                 a face (v0 v1 v2 v3), fanned from v0, its smallest
         |\\                  global vertex id: triangles (v0 v1 v2), (v0 v2 v3);
         | \\                 each with the apex a tetrahedron
        v3--v2
        |  / |
        v0--v1

Conformity: a face shared by two elements must be split the same way from both
sides, so the rule depends on the face's own nodes only: fan from the face's
smallest global vertex id.  The apex is the element's smallest global vertex id,
so a face that contains the apex is fanned from the apex too (it is also that
face's smallest id): the cones' faces on it agree with the rule, and every face
of the mesh is split once, the same way, whichever element looks at it.

No new vertex and no new circumsphere: every tetrahedron lies on its parent's
sphere, so the box method's signed pieces of the tetrahedra add up to the
parent's pieces exactly (the triangles inside the parent are met twice, with
opposite orientations), and an edge that the split adds (a diagonal of a polygon
face, or one through the element) gets the coupling ``0`` exactly.  The tests
prove both with exact arithmetic (:func:`cospherical.mesh.dual.mesh_dual` on the
tetrahedra against the mesh's own dual).

A face's triangles are numbered counter-clockwise seen from outside its element,
as the face cycles are; a tetrahedron ``(apex, t0, t1, t2)`` over the outward
triangle ``(t0, t1, t2)`` therefore has a positive volume
``(t0 - apex) . ((t1 - apex) x (t2 - apex)) > 0``, the orientation of VTK's and
Gmsh's 4-node tetrahedron.

Examples
--------
>>> from cospherical.core.configuration import Box
>>> from cospherical.mesh.octree import build_octree, parse_shape
>>> from cospherical.mesh.assembly import assemble
>>> mesh = assemble(build_octree(Box.parse([1, 1, 1]), 1, [parse_shape("point:0.5,0.5,0.5")]))
>>> tets = split_tetrahedra(mesh)
>>> len(mesh), len(tets), sorted(set(np.bincount(tets.parent).tolist()))
(8, 48, [6])
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING, Any, Iterable, Protocol, Sequence, TypeVar

import numpy as np
from numpy.typing import NDArray

from ..core.geometry import Rational
from .assembly import ElementBlock, Mesh

if TYPE_CHECKING:
    from .dual import Dual
    from .regions import RegionFaces

__all__ = ["SIDES", "BoundaryTriangles", "ElementSource", "SimplexMesh", "Tetrahedra", "boundary_triangles", "fan_triangles",
           "dual_simplex_mesh", "element_blocks", "simplex_mesh", "split_tetrahedra"]


@dataclass(frozen=True)
class Tetrahedra:
    """A mesh's elements split into tetrahedra.

    ``nodes``: (t x 4) global vertex ids, positively oriented; ``parent``: the
    element each came from (tetrahedra are listed element by element, in the
    mesh's element order); ``region``: the parent's region (all 0 in a mesh of one
    region).
    """

    nodes: NDArray[np.int64]
    parent: NDArray[np.int64]
    region: NDArray[np.int32]

    def __len__(self) -> int:
        return len(self.nodes)


@dataclass(frozen=True)
class BoundaryTriangles:
    """The element faces in the domain's six sides, split as :func:`split_tetrahedra` splits them.

    ``nodes``: (f x 3) global vertex ids, counter-clockwise seen from outside the
    domain; ``parent``: the element each belongs to; ``side``: which side, ``2 * axis
    + (0 at the low end, 1 at the high end)``, in the order of :data:`SIDES`.
    """

    nodes: NDArray[np.int64]
    parent: NDArray[np.int64]
    side: NDArray[np.int8]

    def __len__(self) -> int:
        return len(self.nodes)


_Id = TypeVar("_Id", bound=np.integer[Any])  # vertex ids keep their dtype through fan_triangles

SIDES = ("xmin", "xmax", "ymin", "ymax", "zmin", "zmax")


def fan_triangles(face: NDArray[_Id]) -> NDArray[_Id]:
    """Triangles of polygons (rows of global ids, in cycle order) fanned from each row's smallest id.

    Returns (rows x (k - 2) x 3), each triangle in the cycle's orientation.

    >>> fan_triangles(np.array([[5, 2, 7, 9], [1, 3, 4, 8]])).tolist()
    [[[2, 7, 9], [2, 9, 5]], [[1, 3, 4], [1, 4, 8]]]
    """
    rows, k = face.shape
    start = np.argmin(face, axis=1)
    r = np.arange(rows)[:, None]
    steps = np.arange(1, k - 1)[None]
    first = face[np.arange(rows), start][:, None].repeat(k - 2, axis=1)
    second = face[r, (start[:, None] + steps) % k]
    third = face[r, (start[:, None] + steps + 1) % k]
    return np.stack([first, second, third], axis=2)


class ElementSource(Protocol):
    """What :func:`split_tetrahedra` reads of a mesh: its elements (:meth:`blocks`), their count and regions.

    :class:`~cospherical.mesh.assembly.Mesh` is one; a bare element list (a ``dual.npz``'s) is another.
    ``element_region``: per element its region's index, ``None`` for a mesh of one region.
    """

    def __len__(self) -> int: ...

    @property
    def element_region(self) -> NDArray[np.integer[Any]] | None: ...

    def blocks(self) -> Iterable[ElementBlock]: ...


def _regions(mesh: ElementSource) -> NDArray[np.int32]:
    region = mesh.element_region
    return np.zeros(len(mesh), dtype=np.int32) if region is None else np.asarray(region, dtype=np.int32)


def split_tetrahedra(mesh: ElementSource, blocks: Iterable[ElementBlock] | None = None) -> Tetrahedra:
    """Every element of ``mesh`` split into tetrahedra (see the module's docstring for the rule).

    ``blocks``: the elements as :meth:`~cospherical.mesh.assembly.Mesh.blocks` gives them
    (default: the mesh's own), for example :func:`element_blocks` of an element list.
    """
    parts, parents = [], []
    for rows, nodes, faces, _ in (mesh.blocks() if blocks is None else blocks):
        nodes = np.asarray(nodes, dtype=np.int64)
        apex = nodes.min(axis=1)
        for cycle in faces:
            face = nodes[:, list(cycle)]
            away = ~(face == apex[:, None]).any(axis=1)  # faces that hold the apex are in no cone
            if not away.any():
                continue
            triangles = fan_triangles(face[away])
            count = triangles.shape[1]
            tops = np.broadcast_to(apex[away, None, None], (int(away.sum()), count, 1))
            parts.append(np.concatenate([tops, triangles], axis=2).reshape(-1, 4))
            parents.append(np.repeat(np.asarray(rows)[away], count))
    if not parts:
        return Tetrahedra(np.zeros((0, 4), dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int32))
    tets, parent = np.concatenate(parts), np.concatenate(parents)
    order = np.argsort(parent, kind="stable")  # element by element: a deterministic order, whatever the blocks
    parent = parent[order]
    return Tetrahedra(tets[order], parent, _regions(mesh)[parent])


def element_blocks(grid_vertices: NDArray[np.integer[Any]], squared: Sequence[Rational],
                   nodes: NDArray[np.integer[Any]], sizes: NDArray[np.integer[Any]]) -> list[ElementBlock]:
    """Blocks (as :meth:`~cospherical.mesh.assembly.Mesh.blocks` gives them) of an element list on grid vertices.

    For elements known only by their vertices (a ``dual.npz``): each distinct shape, up to
    translation and scaling by powers of two, gets its faces from its exact hull once.
    """
    from ..core.geometry import Frame
    from ..core.polyhedron import measure
    from ..errors import InputError

    verts = np.asarray(grid_vertices, dtype=np.int64)
    by_shape: dict[tuple[tuple[int, ...], ...], list[int]] = {}
    for e in range(len(nodes)):
        ids = np.asarray(nodes[e, :int(sizes[e])], dtype=np.int64)
        rel = verts[ids] - verts[ids].min(axis=0)
        scale = math.gcd(*(int(x) for x in rel.reshape(-1)))
        scale = scale & -scale
        by_shape.setdefault(tuple(tuple(row) for row in (rel // scale).tolist()), []).append(e)
    blocks = []
    for key, rows in by_shape.items():
        points = {n: tuple(Fraction(int(x)) for x in p) for n, p in enumerate(key)}
        element = measure(Frame.build(points, squared), range(len(key)))
        if not element.cycles:
            raise InputError(f"element {rows[0]} is flat: it has no tetrahedra")
        ids = np.array(rows, dtype=np.int64)
        blocks.append(ElementBlock(ids, np.asarray(nodes)[ids, :len(key)].astype(np.int64), element.cycles, None))
    return blocks


def boundary_triangles(mesh: Mesh | Dual, blocks: Iterable[ElementBlock] | None = None) -> BoundaryTriangles:
    """The triangles of the element faces that lie in the domain's sides (the outer surface, split conformingly).

    ``blocks``: the elements (default: the mesh's own); a :class:`~cospherical.mesh.dual.Dual`'s
    must be given (:func:`element_blocks`).
    """
    grid = int(mesh.grid)
    vertices = np.asarray(mesh.vertices if isinstance(mesh, Mesh) else mesh.grid_vertices, dtype=np.int64)
    if blocks is None:
        if not isinstance(mesh, Mesh):
            raise TypeError("boundary_triangles: a Dual's elements are given as blocks (element_blocks)")
        blocks = mesh.blocks()
    parts: list[NDArray[np.int64]] = []
    parents: list[NDArray[np.int64]] = []
    sides: list[NDArray[np.int8]] = []
    for rows, block_nodes, faces, _ in blocks:
        nodes = np.asarray(block_nodes, dtype=np.int64)
        for cycle in faces:
            face = nodes[:, list(cycle)]
            coords = vertices[face]  # rows x k x 3
            for axis in range(3):
                for end, value in enumerate((0, grid)):
                    on = (coords[:, :, axis] == value).all(axis=1)
                    if not on.any():
                        continue
                    triangles = fan_triangles(face[on])
                    parts.append(triangles.reshape(-1, 3))
                    parents.append(np.repeat(np.asarray(rows)[on], triangles.shape[1]))
                    sides.append(np.full(parents[-1].shape, 2 * axis + end, dtype=np.int8))
    if not parts:
        return BoundaryTriangles(np.zeros((0, 3), dtype=np.int64), np.zeros(0, dtype=np.int64),
                                 np.zeros(0, dtype=np.int8))
    corners, parent, side = np.concatenate(parts), np.concatenate(parents), np.concatenate(sides)
    order = np.lexsort((parent, side))  # side by side, element by element: deterministic
    return BoundaryTriangles(corners[order], parent[order], side[order])


@dataclass(frozen=True)
class SimplexMesh:
    """A mesh as a solver that reads simplices takes it: tetrahedra in named volumes, triangles in named surfaces.

    ``points``: (n x 3) real coordinates of the mesh's vertices (same ids);
    ``tetrahedra`` (t x 4) with ``volume`` (t,) indices into ``volumes`` (the region
    names); ``triangles`` (f x 3, counter-clockwise seen from outside the domain or
    from the surface's first region) with ``surface`` (f,) indices into ``surfaces``.
    A mesh of one region has the volume ``domain`` and the six sides of the box as
    surfaces (:data:`SIDES`), where a solver puts its boundary conditions.
    """

    points: NDArray[np.float64]
    tetrahedra: NDArray[np.int64]
    volume: NDArray[np.int32]
    volumes: tuple[str, ...]
    triangles: NDArray[np.int64]
    surface: NDArray[np.int32]
    surfaces: tuple[str, ...]


def simplex_mesh(mesh: Mesh, tetrahedra: Tetrahedra | None = None, faces: RegionFaces | None = None) -> SimplexMesh:
    """The mesh's tetrahedra per region and its named surfaces (see :class:`SimplexMesh`).

    A device's mesh (regions from a device file) gives one volume per region, named as
    the region, and one surface per contact and per interface (``"a|b"``), their
    polygons fanned by the rule of :func:`split_tetrahedra` (so their triangles are
    faces of the tetrahedra); its points are in device units (the device's origin
    added).  ``faces``: the device's :class:`~cospherical.mesh.regions.RegionFaces`
    when already computed.  Any other mesh: the volume ``domain`` and the box's sides.
    """
    blocks = list(mesh.blocks())
    tets = split_tetrahedra(mesh, blocks) if tetrahedra is None else tetrahedra
    regions = mesh.regions
    if regions is None or regions.layout is None:
        outer = boundary_triangles(mesh, blocks)
        return SimplexMesh(mesh.points(), tets.nodes, tets.region, ("domain",), outer.nodes,
                           outer.side.astype(np.int32), SIDES)
    from .regions import region_faces

    faces = region_faces(mesh) if faces is None else faces
    device = regions.layout.device
    contacts = tuple(c.name for c in device.contacts)
    surfaces = contacts + tuple(faces.interface_names)
    parts = [_fanned(faces.contact_nodes, faces.contact_face_contact),
             _fanned(faces.interface_nodes, np.asarray(faces.interface_face_interface) + len(contacts))]
    triangles = np.concatenate([p[0] for p in parts])
    surface = np.concatenate([p[1] for p in parts]).astype(np.int32)
    order = np.argsort(surface, kind="stable")  # surface by surface, each in its faces' order
    points = mesh.points() + np.array([float(x) for x in device.origin])
    return SimplexMesh(points, tets.nodes, tets.region, tuple(regions.names), triangles[order], surface[order],
                       surfaces)


def _fanned(polygons: np.ndarray, label: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Triangles of -1 padded polygons (fanned from each one's smallest id) and each triangle's label."""
    label = np.asarray(label, dtype=np.int64)
    polygons = np.asarray(polygons, dtype=np.int64)
    # none (a device of one region has no interface): numpy cannot reshape an empty array to (0, -1)
    polygons = polygons.reshape(len(label), -1) if polygons.size else np.zeros((len(label), 0), dtype=np.int64)
    sizes = (polygons >= 0).sum(axis=1)
    triangles, labels, rows = [np.zeros((0, 3), dtype=np.int64)], [np.zeros(0, dtype=np.int64)], []
    for k in np.unique(sizes):
        which = np.flatnonzero(sizes == k)
        fans = fan_triangles(polygons[which, :k])
        triangles.append(fans.reshape(-1, 3))
        labels.append(np.repeat(label[which], k - 2))
        rows.append(np.repeat(which, k - 2))
    order = np.argsort(np.concatenate(rows), kind="stable") if rows else np.zeros(0, dtype=np.int64)
    return np.concatenate(triangles)[order], np.concatenate(labels)[order]


def dual_simplex_mesh(dual: Dual) -> SimplexMesh:
    """:func:`simplex_mesh` of the elements a :class:`~cospherical.mesh.dual.Dual` holds (a ``dual.npz``).

    With a device's parts (``dual.regions``): a volume per region, a surface per contact
    (its faces fanned) and per interface, the triangles where tetrahedra of two regions
    meet, named ``"a|b"`` (``a`` the lower region index) and oriented out of ``a``.
    """
    blocks = element_blocks(dual.grid_vertices, dual.box.squared, dual.element_nodes, dual.element_sizes)
    parts = dual.regions
    count = len(dual.element_sizes)
    tets = split_tetrahedra(_ElementList(count, None if parts is None else parts.element_region, blocks))
    points = np.asarray(dual.vertices, dtype=np.float64)
    if parts is None:
        outer = boundary_triangles(dual, blocks)
        return SimplexMesh(points, tets.nodes, tets.region, ("domain",), outer.nodes, outer.side.astype(np.int32),
                           SIDES)
    contacts = _fanned(parts.contact_face_nodes, parts.contact_face_contact)
    between, pairs = _interfaces(tets)
    names = tuple(parts.contact_names) + tuple(f"{parts.names[a]}|{parts.names[b]}" for a, b in pairs)
    triangles = np.concatenate([contacts[0], between[0]])
    surface = np.concatenate([contacts[1], between[1] + len(parts.contact_names)]).astype(np.int32)
    order = np.argsort(surface, kind="stable")
    return SimplexMesh(points, tets.nodes, tets.region, tuple(parts.names), triangles[order], surface[order], names)


def _interfaces(tets: Tetrahedra) -> tuple[tuple[np.ndarray, np.ndarray], list[tuple[int, int]]]:
    """The triangles shared by tetrahedra of two regions, out of the lower region, with their pair's index."""
    outward = tets.nodes[:, [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]]].reshape(-1, 3)
    region = np.repeat(tets.region, 4)
    keys = np.sort(outward, axis=1)
    order = np.lexsort((region, keys[:, 2], keys[:, 1], keys[:, 0]))
    keys, outward, region = keys[order], outward[order], region[order]
    same = (keys[1:] == keys[:-1]).all(axis=1) & (region[1:] != region[:-1])
    first = np.flatnonzero(same)  # the lower region's copy comes first (sorted by region)
    pair_rows = np.column_stack([region[first], region[first + 1]])
    pairs = sorted({(int(a), int(b)) for a, b in pair_rows.tolist()})
    index = {p: k for k, p in enumerate(pairs)}
    labels = np.array([index[int(a), int(b)] for a, b in pair_rows.tolist()], dtype=np.int64)
    return (outward[first], labels), pairs


class _ElementList:
    """``count`` elements with their regions (or one region), for :func:`split_tetrahedra` given its blocks."""

    def __init__(self, count: int, element_region: NDArray[np.integer[Any]] | None,
                 blocks: Sequence[ElementBlock]) -> None:
        self.count = count
        self.element_region = element_region
        self._blocks = blocks

    def __len__(self) -> int:
        return self.count

    def blocks(self) -> Sequence[ElementBlock]:
        return self._blocks
