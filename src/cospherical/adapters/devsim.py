"""DEVSIM with the exact dual: a mesh handed to the box-method TCAD simulator in memory.

DEVSIM (``pip install cospherical[devsim]``) is a vertex-centred finite-volume
simulator: every equation it assembles integrates edge fluxes times the region's
edge coupling (the area of the dual face of an edge) and node terms times the
node volume (the control volume).  It computes both itself from tetrahedra, one
tetrahedron at a time, adding the *magnitudes* of the pieces (its
``TetrahedronEdgeCouple.cc``, line 99 at commit a22d841:
``0.5 * (magnitude(cross_prod(v0, v1)) + magnitude(cross_prod(v0, v2)))``).  On a
Delaunay mesh whose circumcentres all lie inside their own tetrahedra that is the
Voronoi dual; on a graded octree mesh many circumcentres lie beyond a face, the
Voronoi dual counts that piece negative, and DEVSIM's sum is too large: its node
volumes add up to 1.09-1.14 of a graded unit cube, 10.3 instead of 8 on a 1 x 2 x 4
box, and a linear potential comes out wrong by several per cent.

:func:`create_device` therefore builds DEVSIM's mesh from this tool's conforming
tetrahedra (:mod:`cospherical.mesh.tetrahedra`) and installs the exact dual
(:func:`cospherical.mesh.dual.mesh_dual`) in every region: a node model
``ExactNodeVolume`` and an edge model ``ExactEdgeCouple``, selected by the region
parameters ``node_volume_model`` and ``edge_couple_model`` that DEVSIM's equation
assembly reads (``Equation.cc``: ``GetRegion().GetNodeVolumeModel()``,
``GetEdgeCoupleModel()``).  Every equation defined afterwards uses them; the
diagonals that the split adds couple ``0``, exactly as in the mixed mesh.  A device's
interfaces get each node's exact part of the interface's area as ``ExactSurfaceArea``,
selected by the region parameter ``surface_area_model`` that DEVSIM's interface equations
read (``Interface::GetSurfaceAreaModel``; DEVSIM's own ``SurfaceArea`` holds the same
total from its triangles).

DEVSIM's own geometry stays available under its names (``NodeVolume``,
``EdgeCouple``) for comparison, and so do the element edge models
(``ElementEdgeCouple``), which only element-based models use.

Examples
--------
>>> from cospherical.core.configuration import Box
>>> from cospherical.mesh.assembly import assemble
>>> from cospherical.mesh.octree import build_octree, parse_shape
>>> mesh = assemble(build_octree(Box.parse([1, 2, 4]), 2, [parse_shape("point:0.2,0.3,0.4")]))
>>> handed = create_device(mesh, device="doctest")
>>> import devsim
>>> round(sum(devsim.get_node_model_values(device="doctest", region="domain", name=EXACT_NODE_VOLUME)), 12)
8.0
>>> devsim.delete_device(device="doctest"); devsim.delete_mesh(mesh="doctest")
"""

from __future__ import annotations

import contextlib
import importlib
import io
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Iterable, Protocol, Sequence, Union

import numpy as np

from ..errors import InputError, shown
from ..mesh.assembly import Mesh
from ..mesh.dual import Dual, RegionParts
from ..mesh.tetrahedra import SimplexMesh

__all__ = ["EXACT_EDGE_COUPLE", "EXACT_NODE_VOLUME", "EXACT_SURFACE_AREA", "MeshInput", "DevsimDevice", "MeshWithDual", "create_device",
           "import_devsim"]

EXACT_NODE_VOLUME = "ExactNodeVolume"
EXACT_EDGE_COUPLE = "ExactEdgeCouple"
EXACT_SURFACE_AREA = "ExactSurfaceArea"
CONTACT_MATERIAL = "metal"


class MeshWithDual(Protocol):
    """What :func:`create_device` reads of a mesh object: its assembled mesh and its exact dual.

    The API's :class:`~cospherical.api.mesh.OctreeMesh` is one (the API sits above the
    adapters, so it is named here by what it has, not imported); its dual is computed once
    and carries a device's parts per region.
    """

    @property
    def assembled(self) -> Mesh: ...

    @property
    def dual(self) -> Dual: ...


# What create_device builds from: a mesh object with its dual, an assembled mesh (its dual computed
# here), or a mesh folder holding dual.npz (``cospherical mesh --dual --out DIR``).
MeshInput = Union[MeshWithDual, Mesh, str, Path]


def import_devsim() -> ModuleType:
    """DEVSIM's module, its BLAS configured first (``devsim_openblas``), or one clear error when it is missing."""
    import sys

    if sys.modules.get("devsim") is not None:  # configured once, before its first import (configure refuses to run after it)
        return sys.modules["devsim"]
    try:
        import devsim_openblas

        devsim_openblas.configure()
        devsim = importlib.import_module("devsim")  # a module to the checker (devsim has no type information)
    except ImportError as error:
        raise InputError(f"DEVSIM is not installed ({error.name or error}): pip install 'cospherical[devsim]'") from None
    return devsim


@dataclass(frozen=True)
class DevsimDevice:
    """What :func:`create_device` made: the device's name, its regions and contacts, the mesh handed over.

    ``node_ids[region]``: for each of DEVSIM's nodes of that region (DEVSIM's order), the
    mesh's vertex id; ``edge_ids[region]``: for each of DEVSIM's edges, the index into the
    dual's edges, or -1 for an edge that the tetrahedral split added (coupling 0).
    """

    name: str
    regions: tuple[str, ...]
    contacts: tuple[str, ...]
    simplices: SimplexMesh
    dual: Dual
    node_ids: dict[str, np.ndarray]
    edge_ids: dict[str, np.ndarray]
    interfaces: tuple[str, ...] = ()
    log: str = ""


# A region's exact geometry for DEVSIM: node volume per vertex, dual-face area per edge, surface area per vertex
# (None: a dual without interfaces).
RegionGeometry = tuple[np.ndarray, np.ndarray, "np.ndarray | None"]


@dataclass(frozen=True)
class _Source:
    """What a device is built from: the simplices, the dual, per region its node volumes and edge areas
    (region name -> (volume per vertex, area per dual edge)), each contact's region."""

    simplices: SimplexMesh
    dual: Dual
    geometry: dict[str, RegionGeometry]
    contact_region: dict[str, str]
    materials: tuple[str, ...] = ()


def _source(mesh: MeshInput) -> _Source:
    """The simplices and exact geometry of an API mesh, an assembled mesh, or a mesh folder holding dual.npz."""
    from ..mesh.dual import mesh_dual
    from ..mesh.tetrahedra import dual_simplex_mesh, simplex_mesh

    if isinstance(mesh, (str, Path)):
        from ..formats.dual import read_dual, verify_dual

        folder = Path(mesh)
        if not folder.is_dir():
            raise InputError(f"{shown(str(folder))}: not a mesh folder (write one with cospherical mesh --dual "
                             "--out DIR)")
        path = folder / "dual.npz"
        if not path.is_file():
            raise InputError(f"{shown(str(folder))}: not a mesh folder with dual.npz (write one with cospherical "
                             "mesh --dual --out DIR)")
        dual = read_dual(path)
        # a file on disk is anyone's: a value changed and its checksum renewed would reach DEVSIM as it is
        verify_dual(dual, path)
        simplices = dual_simplex_mesh(dual)
        if dual.regions is None:
            return _Source(simplices, dual, {"domain": (dual.control_volume, dual.area, None)}, {})
        parts = dual.regions
        return _Source(simplices, dual, _region_geometry(dual, parts),
                       {name: parts.names[r] for name, r in zip(parts.contact_names, parts.contact_regions)},
                       tuple(parts.materials))
    if isinstance(mesh, Mesh):
        assembled, dual = mesh, mesh_dual(mesh)
    elif isinstance(getattr(mesh, "assembled", None), Mesh):  # the API's mesh holds the assembled one
        # and computes its dual once (with its parts per region)
        assembled, dual = mesh.assembled, mesh.dual
    else:  # a caller without a type checker can hand in anything
        raise InputError(f"create_device: {type(mesh).__name__} is not a mesh (give the API's mesh, "
                         "an assembled mesh or a mesh folder)")
    regions = getattr(assembled, "regions", None)
    if regions is None or regions.layout is None:
        simplices = simplex_mesh(assembled)
        return _Source(simplices, dual, {"domain": (dual.control_volume, dual.area, None)}, {})
    from ..mesh.pipeline import full_dual
    from ..mesh.regions import region_faces

    faces = region_faces(assembled)
    simplices = simplex_mesh(assembled, faces=faces)
    dual = full_dual(assembled, faces, dual)  # with its parts per region
    assert dual.regions is not None
    geometry = _region_geometry(dual, dual.regions)
    device = regions.layout.device
    return _Source(simplices, dual, geometry, {c.name: c.region for c in device.contacts}, tuple(regions.materials))


def _region_geometry(dual: Dual, parts: RegionParts) -> dict[str, RegionGeometry]:
    """Per region name: its node volume per vertex, its dual-face area per edge (0 where it has none) and its
    surface area per vertex: its part of the interfaces the region is on, what DEVSIM's ``SurfaceArea`` holds
    (``None`` for a dual without interfaces: a version 4 file)."""
    geometry: dict[str, RegionGeometry] = {}
    interfaces = parts.interfaces
    for r, name in enumerate(parts.names):
        volume = np.zeros(len(dual.vertices))
        rows = parts.volume_region == r
        volume[parts.volume_vertex[rows]] = parts.volume_part[rows]
        area = np.zeros(len(dual.edges))
        rows = parts.coupling_region == r
        edges = parts.coupling_edge[rows]
        area[edges] = parts.coupling_part[rows] * dual.length[edges]
        surface = None
        if interfaces is not None:
            surface = np.zeros(len(dual.vertices))
            touching = np.flatnonzero((interfaces.regions == r).any(axis=1))
            mine = np.isin(interfaces.interface, touching)
            np.add.at(surface, interfaces.vertex[mine], interfaces.part[mine])
        geometry[name] = (volume, area, surface)
    return geometry


def create_device(mesh: MeshInput, device: str = "device", contacts: Sequence[str] | None = None, material: str = "Silicon",
                  scale: float = 1.0) -> DevsimDevice:
    """Build DEVSIM's mesh and device from ``mesh``, the exact dual installed as its geometry.

    ``mesh``: the API's mesh, an assembled :class:`~cospherical.mesh.assembly.Mesh`, or a
    mesh folder with ``dual.npz`` (``cospherical mesh --dual --out DIR``; a device's
    ``dual.npz`` holds its parts per region, its contact faces and its interfaces).

    A device's mesh (``build_mesh(device=...)``) gives one DEVSIM region per region,
    with its name and material, one contact per contact of the device (``contacts``:
    a subset of their names, default all) and one interface per pair of touching
    regions, named ``"a|b"``; each region's node volumes and edge couplings are its
    parts of the exact dual (an interface vertex's control volume and an interface
    edge's dual face split between the regions), and each region's ``ExactSurfaceArea``
    (its ``surface_area_model``) is each node's part of the region's interfaces (not
    from a version 4 ``dual.npz``, which has none: DEVSIM's own then).  Any other mesh gives the region
    ``domain`` of ``material``, and ``contacts`` names which of the box's sides
    (``xmin`` ... ``zmax``) become contacts (default none).

    DEVSIM's mesh is named like the device.  DEVSIM's messages while it builds them
    are kept in :attr:`DevsimDevice.log`, not printed.  ``scale``: DEVSIM's length per
    unit of the mesh (``1e-4`` for a mesh in micrometres, DEVSIM's physics being in
    centimetres): coordinates times ``scale``, couplings (areas) times ``scale**2`` and
    node volumes times ``scale**3``.
    """
    if not (isinstance(scale, (int, float)) and np.isfinite(scale) and scale > 0):
        raise InputError(f"scale {shown(scale)}: must be a positive number")
    if not isinstance(device, str) or not device.strip() or len(device) > 200 or not device.isprintable():
        raise InputError(f"device name {shown(device)}: must be a non-empty printable name")
    if contacts is not None and (not isinstance(contacts, (list, tuple)) or not all(isinstance(c, str) for c in contacts)):
        # a string would be taken letter by letter
        raise InputError(f"contacts={shown(contacts)}: a list of contact names, such as ['gate']")
    devsim = import_devsim()
    if device in devsim.get_device_list() or device in devsim.get_mesh_list():
        raise InputError(f"device {shown(device)}: DEVSIM already has a device or mesh of that name")
    source = _source(mesh)
    simplices = source.simplices
    points = simplices.points * float(scale)
    named = tuple(source.contact_region) if source.contact_region else simplices.surfaces
    contacts = tuple(source.contact_region) if contacts is None and source.contact_region else tuple(contacts or ())
    unknown = [c for c in contacts if c not in named]
    if unknown:
        raise InputError(f"contact {shown(unknown[0])}: the mesh's contacts are {', '.join(named) or 'none'}")
    interfaces = [name for name in simplices.surfaces if name not in named]
    names = list(simplices.volumes) + list(simplices.surfaces)
    offset = len(simplices.volumes)
    elements = np.concatenate([
        np.column_stack([np.full(len(simplices.triangles), 2), simplices.surface + offset, simplices.triangles]
                        ).reshape(-1),
        np.column_stack([np.full(len(simplices.tetrahedra), 3), simplices.volume, simplices.tetrahedra]).reshape(-1)])
    materials = {name: given or material for name, given in zip(simplices.volumes, source.materials or
                                                                 ("",) * len(simplices.volumes))}
    log = io.StringIO()
    try:
        with contextlib.redirect_stdout(log):  # DEVSIM prints through Python's sys.stdout
            devsim.create_gmsh_mesh(mesh=device, coordinates=points.reshape(-1).tolist(),
                                    physical_names=names, elements=elements.astype(np.int64).tolist())
            for name in simplices.volumes:
                devsim.add_gmsh_region(gmsh_name=name, mesh=device, region=name, material=materials[name])
            for name in contacts:
                devsim.add_gmsh_contact(gmsh_name=name, mesh=device, name=name,
                                        region=source.contact_region.get(name, simplices.volumes[0]),
                                        material=CONTACT_MATERIAL)
            for name in interfaces:
                first, second = _pair(name, simplices.volumes)
                devsim.add_gmsh_interface(gmsh_name=name, mesh=device, name=name, region0=first, region1=second)
            devsim.finalize_mesh(mesh=device)
            devsim.create_device(mesh=device, device=device)
            node_ids, edge_ids = {}, {}
            for name in simplices.volumes:
                node_ids[name], edge_ids[name] = _install_dual(devsim, device, name, points, source.dual,
                                                               source.geometry[name], float(scale))
    except BaseException as error:
        # nothing half made: DEVSIM keeps what it was given, a later call of the same name would be refused
        with contextlib.redirect_stdout(io.StringIO()):
            if device in devsim.get_device_list():
                devsim.delete_device(device=device)
            if device in devsim.get_mesh_list():
                devsim.delete_mesh(mesh=device)
        if isinstance(error, devsim.error):
            text = " ".join(str(error).split())
            raise InputError(f"DEVSIM refused the mesh of device {shown(device)}: {text[:200]}") from None
        raise
    return DevsimDevice(device, tuple(simplices.volumes), contacts, simplices, source.dual, node_ids, edge_ids,
                        tuple(interfaces), log.getvalue())


def _pair(interface: str, regions: Iterable[str]) -> tuple[str, str]:
    """The two regions of an interface named ``"a|b"`` (region names may hold ``|`` themselves)."""
    for first in regions:
        for second in regions:
            if first != second and interface == f"{first}|{second}":
                return first, second
    raise InputError(f"interface {shown(interface)}: names no two regions")


def _install_dual(devsim: ModuleType, device: str, region: str, points: np.ndarray, dual: Dual, geometry: RegionGeometry,
                  scale: float
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Set the region's exact node volumes, edge couplings and (a device's) surface areas and select them;
    DEVSIM's node and edge maps."""
    volumes, areas, surface = geometry
    xyz = np.column_stack([devsim.get_node_model_values(device=device, region=region, name=axis)
                           for axis in ("x", "y", "z")])
    # DEVSIM keeps the coordinates it was given (doubles): exact equality finds each node's vertex id
    order = np.lexsort(points.T[::-1])
    keys = points[order]
    at = np.searchsorted(_rows(keys), _rows(xyz))
    at = np.minimum(at, len(keys) - 1)
    if not (keys[at] == xyz).all():
        raise InputError(f"DEVSIM region {shown(region)}: a node that is no vertex of the mesh")
    nodes = order[at]
    devsim.edge_from_node_model(device=device, region=region, node_model="node_index")
    ends = np.column_stack([devsim.get_edge_model_values(device=device, region=region, name=f"node_index@n{k}")
                            for k in (0, 1)]).astype(np.int64)
    pairs = np.sort(nodes[ends], axis=1)
    n = np.int64(len(points))
    known = dual.edges[:, 0].astype(np.int64) * n + dual.edges[:, 1]
    wanted = pairs[:, 0] * n + pairs[:, 1]
    where = np.minimum(np.searchsorted(known, wanted), len(known) - 1)
    edges = np.where(known[where] == wanted, where, -1)
    area = np.where(edges >= 0, areas[np.maximum(edges, 0)], 0.0) * scale ** 2
    devsim.node_solution(device=device, region=region, name=EXACT_NODE_VOLUME)
    devsim.set_node_values(device=device, region=region, name=EXACT_NODE_VOLUME,
                           values=(volumes[nodes] * scale ** 3).tolist())
    devsim.edge_solution(device=device, region=region, name=EXACT_EDGE_COUPLE)
    devsim.set_edge_values(device=device, region=region, name=EXACT_EDGE_COUPLE, values=area.tolist())
    devsim.set_parameter(device=device, region=region, name="node_volume_model", value=EXACT_NODE_VOLUME)
    devsim.set_parameter(device=device, region=region, name="edge_couple_model", value=EXACT_EDGE_COUPLE)
    if surface is not None:  # what interface equations integrate their node terms over
        devsim.node_solution(device=device, region=region, name=EXACT_SURFACE_AREA)
        devsim.set_node_values(device=device, region=region, name=EXACT_SURFACE_AREA,
                               values=(surface[nodes] * scale ** 2).tolist())
        devsim.set_parameter(device=device, region=region, name="surface_area_model", value=EXACT_SURFACE_AREA)
    return nodes, edges


def _rows(points: np.ndarray) -> np.ndarray:
    """Rows of three doubles as one sortable key each (their bytes, compared in lexicographic row order)."""
    data = np.ascontiguousarray(points, dtype=np.float64)
    return data.view([("x", "f8"), ("y", "f8"), ("z", "f8")]).reshape(-1)
