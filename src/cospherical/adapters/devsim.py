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
diagonals that the split adds couple ``0``, exactly as in the mixed mesh.

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
import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError, shown

__all__ = ["EXACT_EDGE_COUPLE", "EXACT_NODE_VOLUME", "DevsimDevice", "create_device", "import_devsim"]

EXACT_NODE_VOLUME = "ExactNodeVolume"
EXACT_EDGE_COUPLE = "ExactEdgeCouple"
CONTACT_MATERIAL = "metal"


def import_devsim():
    """DEVSIM's module, its BLAS configured first (``devsim_openblas``), or one clear error when it is missing."""
    import sys

    if sys.modules.get("devsim") is not None:  # configured once, before its first import (configure refuses to run after it)
        return sys.modules["devsim"]
    try:
        import devsim_openblas

        devsim_openblas.configure()
        import devsim
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
    simplices: object
    dual: object
    node_ids: dict
    edge_ids: dict
    log: str = ""


def _source(mesh):
    """(simplices, dual) of an API mesh, an assembled mesh, or a mesh folder holding dual.npz."""
    from ..mesh.dual import mesh_dual
    from ..mesh.tetrahedra import dual_simplex_mesh, simplex_mesh

    if isinstance(mesh, (str, Path)):
        from ..formats.dual import read_dual

        folder = Path(mesh)
        if not folder.is_dir():
            raise InputError(f"{shown(str(folder))}: not a mesh folder (write one with cospherical mesh --dual "
                             "--out DIR)")
        path = folder / "dual.npz"
        if not path.is_file():
            raise InputError(f"{shown(str(folder))}: not a mesh folder with dual.npz (write one with cospherical "
                             "mesh --dual --out DIR)")
        dual = read_dual(path)
        return dual_simplex_mesh(dual), dual
    assembled = getattr(mesh, "assembled", mesh)  # the API's mesh holds the assembled one
    if not hasattr(assembled, "blocks"):
        raise InputError(f"create_device: {type(mesh).__name__} is not a mesh (give the API's mesh, "
                         "an assembled mesh or a mesh folder)")
    dual = getattr(mesh, "dual", None)
    if dual is None or callable(dual):
        dual = mesh_dual(assembled)
    return simplex_mesh(assembled), dual


def create_device(mesh, device: str = "device", contacts=None, material: str = "Silicon") -> DevsimDevice:
    """Build DEVSIM's mesh and device from ``mesh``, the exact dual installed as its geometry.

    ``mesh``: the API's mesh, an assembled :class:`~cospherical.mesh.assembly.Mesh`, or a
    mesh folder with ``dual.npz`` (``cospherical mesh --dual --out DIR``).  The device
    gets one region per region of the mesh (``domain`` with ``material`` in a mesh of
    one region); ``contacts``: the names of the mesh's surfaces that become DEVSIM
    contacts (in a mesh of one region the box's sides, ``xmin`` ... ``zmax``; default
    none).  DEVSIM's mesh is named like the device.  DEVSIM's messages while it builds
    them are kept in :attr:`DevsimDevice.log`, not printed.
    """
    if not isinstance(device, str) or not device.strip() or len(device) > 200 or not device.isprintable():
        raise InputError(f"device name {shown(device)}: must be a non-empty printable name")
    devsim = import_devsim()
    if device in devsim.get_device_list() or device in devsim.get_mesh_list():
        raise InputError(f"device {shown(device)}: DEVSIM already has a device or mesh of that name")
    simplices, dual = _source(mesh)
    contacts = tuple(contacts or ())
    unknown = [c for c in contacts if c not in simplices.surfaces]
    if unknown:
        raise InputError(f"contact {shown(unknown[0])}: the mesh's surfaces are {', '.join(simplices.surfaces)}")
    names = list(simplices.volumes) + list(simplices.surfaces)
    offset = len(simplices.volumes)
    elements = np.concatenate([
        np.column_stack([np.full(len(simplices.triangles), 2), simplices.surface + offset, simplices.triangles]
                        ).reshape(-1),
        np.column_stack([np.full(len(simplices.tetrahedra), 3), simplices.volume, simplices.tetrahedra]).reshape(-1)])
    log = io.StringIO()
    try:
        with contextlib.redirect_stdout(log):  # DEVSIM prints through Python's sys.stdout
            devsim.create_gmsh_mesh(mesh=device, coordinates=simplices.points.reshape(-1).tolist(),
                                    physical_names=names, elements=elements.astype(np.int64).tolist())
            for name in simplices.volumes:
                devsim.add_gmsh_region(gmsh_name=name, mesh=device, region=name, material=material)
            region = simplices.volumes[0]
            for name in contacts:
                devsim.add_gmsh_contact(gmsh_name=name, mesh=device, name=name, region=region,
                                        material=CONTACT_MATERIAL)
            devsim.finalize_mesh(mesh=device)
            devsim.create_device(mesh=device, device=device)
            node_ids, edge_ids = {}, {}
            for name in simplices.volumes:
                node_ids[name], edge_ids[name] = _install_dual(devsim, device, name, simplices.points, dual)
    except devsim.error as error:
        text = " ".join(str(error).split())
        raise InputError(f"DEVSIM refused the mesh of device {shown(device)}: {text[:200]}") from None
    return DevsimDevice(device, tuple(simplices.volumes), contacts, simplices, dual, node_ids, edge_ids,
                        log.getvalue())


def _install_dual(devsim, device: str, region: str, points: np.ndarray, dual) -> tuple[np.ndarray, np.ndarray]:
    """Set the region's exact node volumes and edge couplings and select them; DEVSIM's node and edge maps."""
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
    area = np.where(edges >= 0, dual.area[np.maximum(edges, 0)], 0.0)
    devsim.node_solution(device=device, region=region, name=EXACT_NODE_VOLUME)
    devsim.set_node_values(device=device, region=region, name=EXACT_NODE_VOLUME,
                           values=dual.control_volume[nodes].tolist())
    devsim.edge_solution(device=device, region=region, name=EXACT_EDGE_COUPLE)
    devsim.set_edge_values(device=device, region=region, name=EXACT_EDGE_COUPLE, values=area.tolist())
    devsim.set_parameter(device=device, region=region, name="node_volume_model", value=EXACT_NODE_VOLUME)
    devsim.set_parameter(device=device, region=region, name="edge_couple_model", value=EXACT_EDGE_COUPLE)
    return nodes, edges


def _rows(points: np.ndarray) -> np.ndarray:
    """Rows of three doubles as one sortable key each (their bytes, compared in lexicographic row order)."""
    data = np.ascontiguousarray(points, dtype=np.float64)
    return data.view([("x", "f8"), ("y", "f8"), ("z", "f8")]).reshape(-1)
