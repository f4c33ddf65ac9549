"""A mesh of an octree in one call: :func:`build_mesh` and the object it returns, :class:`OctreeMesh`.

The call runs the mesher's one pipeline (:mod:`cospherical.mesh.pipeline`): the tree
(refined at shapes, a leaf list, or an :class:`~cospherical.mesh.octree.Octree`), each
leaf's elements from a pattern table (or tessellated), the exact Delaunay subdivision
where the leaves' elements are not Delaunay, the exact checks and the report, and on
request the finite-volume dual.  ``cospherical mesh`` is this call with a command line
around it, and :meth:`OctreeMesh.write` writes the files ``mesh --out`` writes, byte for
byte.

Examples
--------
>>> import cospherical
>>> m = cospherical.build_mesh(domain=(1, 1, 1), levels=2, refine=["point:0.1,0.1,0.1"], uniform=False)
>>> m.vertices.shape, len(m.elements), m.report.volume_ok, m.report.delaunay_violations
((46, 3), 48, True, 0)
>>> m.dual.volume_sum()  # the control volumes, exactly: the whole domain
Fraction(1, 1)
"""

from __future__ import annotations

import os
import re
import time
from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, NamedTuple, Sequence

import numpy as np
from numpy.typing import NDArray

from ..core.configuration import Box
from ..core.geometry import Rational
from ..errors import InputError, shown
from ..files.outputs import OutputFolder
from ..formats.gmsh import GMSH_VERSIONS
from ..mesh.assembly import Lookup, Mesh
from ..mesh.octree import Octree, Shape
from ..mesh.pipeline import (PipelineResult, Progress, TreeSource, delaunay_mode, full_dual, run_pipeline,
                             tree_from_device, tree_from_leaves, tree_from_octree, tree_from_refine)
from ..mesh.report import MeshReport

if TYPE_CHECKING:  # the dual's modules are imported when a dual is made, a table's reader when one is read,
    # a device's when a device is meshed
    from concurrent.futures import Executor

    from ..adapters.devsim import MeshWithDual
    from ..formats.patterns import PatternTable
    from ..mesh.dual import Dual
    from ..mesh.device import Device

    # a pattern table: a path to its file, or a table cospherical.load_patterns read
    PatternSource = PatternTable | str | os.PathLike[str]

__all__ = ["Elements", "ExactVertices", "OctreeMesh", "build_mesh", "default_cut", "device_cut_axis", "from_treemesh",
           "mesh_writes", "output_names",
           "pattern_lookup", "piece_name", "tree_source"]


def output_names(dual: bool, device: bool = False, gmsh: bool = False, tets: bool = False) -> tuple[str, ...]:
    """The files a mesh writes into its folder (``mesh --out``, :meth:`OctreeMesh.write`), known before the work.

    ``device``: a device with named faces (:attr:`~cospherical.mesh.device.Device.has_faces`), whose
    contacts and interfaces go to ``contacts.vtu`` (a VTU of no cells, valid VTK, is one meshio cannot read).

    The output folder is locked and these names checked before the mesh is made,
    and its manifest lists them afterwards (a later run removes a file of this one
    that it did not write again).
    """
    return ("mesh.vtu", "report.json", "mesh.png") + (("dual.npz",) if dual else ()) + \
        (("contacts.vtu",) if device else ()) + (("mesh.msh",) if gmsh else ()) + (("tets.vtu",) if tets else ())


def piece_name(k: int) -> str:
    """The file of piece ``k`` of a partitioned mesh (``mesh --partitions N``)."""
    return f"mesh-{k}.vtu"


def mesh_writes(name: str) -> bool:
    """Whether a mesh run writes a file of this name: the only files of an earlier run its folder may remove."""
    piece = re.fullmatch(r"mesh-(0|[1-9][0-9]{0,9})\.vtu", name)
    if piece is None:
        return name in (*output_names(True, True, True, True), "mesh.pvtu")
    from ..mesh.partition import MAX_PARTITIONS  # imported for a piece's name only: a partitioned run wrote it

    return int(piece[1]) < MAX_PARTITIONS


def default_cut(shapes: Sequence[Shape], box: Box) -> float:
    """Where ``mesh.png`` cuts, as a fraction of the domain's height: through the first shape's centre, else half way."""
    if shapes:
        shape = shapes[0]
        if shape.kind in ("sphere", "point"):
            return min(1.0, max(0.0, float(shape.values[2]) / float(box.c)))
        if shape.kind == "box":
            return min(1.0, max(0.0, float(shape.values[2] + shape.values[5]) / 2 / float(box.c)))
    return 0.5


def tree_source(box: Box, levels: int | None = None, refine: Sequence[str | Shape] | None = None, *,
                leaves: str | Path | Sequence[Sequence[int]] | np.ndarray | None = None, tree: Octree | None = None,
                balance: str = "vertex", max_leaves: int | None = None) -> TreeSource:
    """The tree to mesh, from exactly one of ``refine`` (with ``levels``), ``leaves`` or ``tree``.

    ``leaves``: a leaf list file (text ``level i j k`` lines or JSON, see
    :func:`cospherical.formats.mesh.read_leaves`) or its rows ``(level, i, j, k)``.
    """
    given = [name for name, value in (("refine", refine), ("leaves", leaves), ("tree", tree)) if value is not None]
    if len(given) != 1:
        raise InputError("give the tree one way: refine= (with levels=), leaves= or tree="
                         + (f", not {' and '.join(given)}" if given else ""))
    if refine is not None:
        if isinstance(refine, (str, Shape)):
            refine = [refine]
        if levels is None:
            raise InputError("refine= needs levels=")
        return tree_from_refine(box, levels, refine, balance, max_leaves)
    if levels is not None:
        raise InputError(f"levels= goes with refine=, not with {given[0]}=")
    if tree is not None:
        if not isinstance(tree, Octree):
            raise InputError(f"tree=: an Octree, not {type(tree).__name__}")
        return tree_from_octree(tree)
    if isinstance(leaves, (str, Path)):
        from ..formats.mesh import read_leaves

        level_list, positions = read_leaves(leaves, max_leaves)
        return tree_from_leaves(box, level_list, positions, where=str(leaves), file=Path(leaves).name)
    from ..mesh.octree import check_leaf_count

    if not isinstance(leaves, (Sequence, np.ndarray)):
        raise InputError(f"leaves=: a leaf list file or rows of (level, i, j, k), not {type(leaves).__name__}")
    check_leaf_count(len(leaves), "leaves=:", max_leaves)  # before a row is converted
    try:
        rows = np.asarray(leaves)
    except (ValueError, TypeError, OverflowError):
        rows = np.asarray(None)
    if rows.ndim != 2 or rows.shape[1] != 4 or rows.dtype.kind not in "iu" or rows.dtype.itemsize > 8:
        raise InputError(f"leaves=: rows of four integers (level, i, j, k), not an array of shape {rows.shape} "
                         f"and type {rows.dtype}")
    return tree_from_leaves(box, rows[:, 0].astype(np.int64), rows[:, 1:].astype(np.int64))


def pattern_lookup(patterns: PatternSource | None, criterion: str, box: Box,
                   every_criterion: bool = False) -> tuple[Lookup | None, str | None]:
    """The lookup of a pattern table (a path, or a table :func:`cospherical.load_patterns` read) and its name for the report.

    Each entry used is checked under ``criterion``, or under every criterion of the table with
    ``every_criterion`` (see :func:`~cospherical.formats.mesh.table_lookup`).
    """
    lookup, name, _ = _pattern_lookup(patterns, criterion, box, every_criterion)
    return lookup, name


def _pattern_lookup(patterns: PatternSource | None, criterion: str, box: Box,
                    every_criterion: bool = False) -> tuple[Lookup | None, str | None, str | None]:
    """:func:`pattern_lookup`, and why the table's entries were not checked (``None``: they are checked).

    A table file whose bytes are a committed table's (:func:`~cospherical.formats.mesh.checked_table`)
    has its entries proven; with ``every_criterion`` (``--check all``) they are checked all the same.
    """
    if patterns is None:
        return None, None, None
    from ..catalogue import shipped_catalogue
    from ..formats.mesh import checked_table, load_table, table_lookup
    from ..formats.patterns import PatternTable

    if isinstance(patterns, PatternTable):  # read by the caller: named by its study, it has no file name here
        return (table_lookup(patterns, criterion, box, every_criterion=every_criterion),
                f"{patterns.header.get('study', 'pattern')} table", None)
    path = Path(patterns)
    table, digest = load_table(path)
    catalogue = shipped_catalogue()
    proven = None if every_criterion else checked_table(digest, catalogue)
    return (table_lookup(table, criterion, box, str(path), catalogue, every_criterion=every_criterion,
                         check_entries=proven is None), path.name, proven)


class ExactVertices(NamedTuple):
    """The vertices exactly: ``coordinates[i, k] * length_k / intervals`` is vertex ``i``'s coordinate along axis ``k``.

    ``coordinates`` (n x 3, int64) are points of the grid of ``intervals`` steps per
    domain side (half the finest leaf), ``box`` the domain with its exact lengths
    (``box.texts``; ``box.squared`` their exact squares, rational also for ``sqrt(2)``
    sides).  :meth:`fractions` gives each coordinate as a fraction of its side.
    """

    coordinates: NDArray[np.int64]
    intervals: int
    box: Box

    def fractions(self) -> list[list[Any]]:
        """Each vertex as three exact :class:`~fractions.Fraction` of the domain's sides (Python lists; slow on big meshes)."""
        from fractions import Fraction

        return [[Fraction(int(x), self.intervals) for x in row] for row in self.coordinates.tolist()]


@dataclass(frozen=True)
class Elements:
    """The elements of a mesh as flat arrays, in the mesh's element order.

    Element ``e`` is of type ``type_ids[types[e]]`` (named ``type_names[...]``; its VTK
    cell ``vtk_cells[...]``: ``tetra``, ``pyramid``, ``wedge``, ``hexahedron`` with nodes
    in VTK order, or ``None`` for a general polyhedron) and has the vertices
    ``connectivity[offsets[e]:offsets[e + 1]]`` (indices into the mesh's vertices, in
    the type's reference order); ``leaf[e]`` is the leaf it lies in (a cell of the
    global Delaunay step that spans leaves: its first leaf), numbered as the tree's
    source numbers them (the leaf list's order when one was given).
    """

    type_ids: tuple[str, ...]
    type_names: tuple[str, ...]
    vtk_cells: tuple[str | None, ...]
    types: NDArray[np.int32]
    connectivity: NDArray[np.int64]
    offsets: NDArray[np.int64]
    leaf: NDArray[np.int64]

    def __len__(self) -> int:
        return len(self.types)

    def nodes(self, element: int) -> NDArray[np.int64]:
        """The vertex ids of one element."""
        return self.connectivity[self.offsets[element]:self.offsets[element + 1]]

    def sizes(self) -> NDArray[np.int64]:
        """Vertices per element."""
        return np.diff(self.offsets)


class OctreeMesh:
    """A meshed octree: vertices, elements, the exact report, the dual, and its files and conversions.

    Made by :func:`build_mesh`.  ``vertices``
    are floats; ``exact_vertices`` the same points exactly (:class:`ExactVertices`);
    ``elements`` an :class:`Elements` view; ``report`` a frozen
    :class:`~cospherical.mesh.report.MeshReport`; ``dual`` the exact finite-volume
    dual (:class:`~cospherical.mesh.dual.Dual`), computed on first use unless the
    mesh was built with ``dual=True``; ``assembled`` the mesher's own
    :class:`~cospherical.mesh.assembly.Mesh` (leaf by leaf, for the lower-level functions).
    """

    def __init__(self, result: PipelineResult, origin: Sequence[Rational | float] = (0.0, 0.0, 0.0)) -> None:
        self._result = result
        self._dual = result.dual
        self.origin = tuple(float(x) for x in origin)

    def __repr__(self) -> str:
        r = self.report
        return (f"OctreeMesh({' x '.join(r.domain)}: {r.leaves:,} leaves, {r.vertices:,} vertices, "
                f"{r.elements:,} elements, {r.types} types)")

    @property
    def assembled(self) -> Mesh:
        """The mesher's own mesh, leaf by leaf (:class:`~cospherical.mesh.assembly.Mesh`), for the lower-level functions."""
        return self._result.mesh

    @property
    def tree(self) -> Octree:
        """The octree meshed (levels and integer positions of its leaves, in the tree's order)."""
        return self._result.source.tree

    @property
    def box(self) -> Box:
        """The domain, with its exact lengths."""
        return self.tree.box

    @property
    def report(self) -> MeshReport:
        """What the exact checks found, the counts and frequencies, and the seconds per stage (frozen)."""
        return self._result.report

    @cached_property
    def vertices(self) -> NDArray[np.float64]:
        """(n, 3) float64: the vertices' coordinates, ``origin`` added (``mesh.vtu``'s points start at 0)."""
        points = self.assembled.points()
        return points + np.array(self.origin) if any(self.origin) else points

    @property
    def exact_vertices(self) -> ExactVertices:
        """The vertices exactly: integer grid coordinates, the grid's steps per side and the domain."""
        mesh = self.assembled
        return ExactVertices(np.asarray(mesh.vertices, dtype=np.int64), int(mesh.grid), mesh.box)

    @cached_property
    def elements(self) -> Elements:
        """The elements: types, vertex ids (flat, with offsets) and leaves, in the mesh's element order."""
        mesh = self.assembled
        conn, sizes = mesh.connectivity()
        ids, element_type = mesh.element_types()
        offsets = np.zeros(len(mesh) + 1, dtype=np.int64)
        np.cumsum(sizes, out=offsets[1:])
        order = self._result.source.leaf_order
        return Elements(tuple(ids), tuple(mesh.type_name(t) for t in ids), tuple(mesh.type_vtk(t) for t in ids),
                        element_type,
                        conn[conn >= 0].astype(np.int64), offsets,
                        (mesh.element_leaf if order is None else order[mesh.element_leaf]).astype(np.int64))

    @property
    def dual(self) -> Dual:
        """The exact finite-volume dual (control volumes, edges, areas, coefficients, ``laplacian()``)."""
        if self._dual is None:
            self._dual = full_dual(self.assembled, self._result.faces)
        return self._dual

    @property
    def violating(self) -> NDArray[np.int64] | None:
        """The elements whose circumsphere strictly holds a vertex (``None``: the check was skipped)."""
        return self._result.violating

    def write(self, folder: str | Path, cut: float | None = None, gmsh: str | None = None, binary: bool = False,
              tets: bool = False) -> None:
        """Write ``mesh.vtu``, ``report.json``, ``mesh.png`` (and ``dual.npz`` when built with ``dual=True``) into ``folder``.

        The files of ``cospherical mesh --out folder``, byte for byte: all of them
        or, on an error, none (the folder is locked and its files renamed into place
        together).  ``cut``: the height of ``mesh.png``'s cut as a fraction of the
        domain's (default :func:`default_cut`).  ``gmsh``: also ``mesh.msh``, the
        mesh split into tetrahedra as a Gmsh file of that version (``"2.2"`` or
        ``"4.1"``; ``binary`` for Gmsh's binary form), with named physical groups
        (:mod:`cospherical.formats.gmsh`); ``tets``: also ``tets.vtu``, the same
        tetrahedra with cell data ``element`` (the parent) and ``region``.
        """
        if not isinstance(folder, (str, Path)) or not str(folder).strip():
            # Path("") is the current folder: the files would land wherever the program runs
            raise InputError(f"folder={shown(folder)}: a folder's path")
        if cut is not None and (isinstance(cut, bool) or not isinstance(cut, (int, float, Fraction))
                                or not 0 <= cut <= 1):
            raise InputError(f"cut={shown(cut)}: the height of mesh.png's cut as a fraction of the domain's, 0..1")
        layout = self._result.source.device
        names = output_names(self.report.dual is not None, layout is not None and layout.device.has_faces,
                             gmsh is not None, tets)
        with OutputFolder(folder, "mesh", names, writes=mesh_writes) as out:
            self.write_files(out.path, cut, gmsh, binary, tets)

    def write_files(self, path: Callable[[str], Path], cut: float | None = None, gmsh: str | None = None,
                    binary: bool = False, tets: bool = False, progress: Progress | None = None) -> None:
        """Write the outputs, each to ``path(name)`` (an :class:`~cospherical.files.outputs.OutputFolder`'s ``path``);
        ``progress("outputs", files, n)`` is told as files are written."""
        report, source = self.report, self._result.source
        if gmsh is not None and gmsh not in GMSH_VERSIONS:
            raise InputError(f"Gmsh version {gmsh!r}: write one of {', '.join(GMSH_VERSIONS)}")
        layout = source.device
        files = len(output_names(report.dual is not None, layout is not None and layout.device.has_faces,
                                 gmsh is not None, tets))

        def wrote(n: int = 1) -> None:
            if progress is not None:
                progress("outputs", files, n)

        if gmsh is not None or tets:
            self._write_tetrahedra(path, gmsh, binary, tets)
            wrote((gmsh is not None) + tets)
        others = files - (gmsh is not None) - tets  # mesh.vtu, mesh.png, report.json, a device's files, dual.npz
        if report.dual is None:
            self._write_mesh_files(path, cut, others, wrote)
            return
        from ..formats.dual.writer import threaded, write_dual

        if not threaded(self.dual):  # a small dual: threads would cost more than they save (formats.deflated)
            self._write_mesh_files(path, cut, others - 1, wrote, with_dual=True)
            write_dual(self.dual, path("dual.npz"))
            wrote()
            return
        from concurrent.futures import ThreadPoolExecutor

        from ..formats.deflated import deflate_workers

        # dual.npz is written beside the other files, in a thread of its own: its time is deflate's and the
        # checksums', which leave the interpreter free for mesh.vtu and mesh.png (the same bytes either way);
        # its error, if any, is raised here once the others are written.  Both files deflate on one pool of
        # threads, one a processor: two pools would ask twice as many threads of the same processors.
        with ThreadPoolExecutor(deflate_workers(), thread_name_prefix="deflate") as deflating, \
                ThreadPoolExecutor(1, thread_name_prefix="dual.npz") as writing:
            written = writing.submit(write_dual, self.dual, path("dual.npz"), deflating)
            self._write_mesh_files(path, cut, others - 1, wrote, with_dual=True, pool=deflating)
            written.result()
        wrote()

    def _write_mesh_files(self, path: Callable[[str], Path], cut: float | None, files: int,
                          wrote: Callable[..., None], with_dual: bool = False, pool: Executor | None = None) -> None:
        """``mesh.vtu``, ``mesh.png`` and ``report.json`` (a device's own files in their place): what
        :meth:`write_files` writes beside dual.npz and the tetrahedra, ``files`` of them; ``pool``: the threads
        that deflate mesh.vtu's blocks (default: its writer's own)."""
        from ..formats.mesh import write_report, write_vtu
        from ..outputs.mesh_picture import cut_png

        mesh, report, source = self.assembled, self.report, self._result.source
        point_data, cell_data = self._vtu_data(with_dual)
        if source.device is not None:
            self._write_device(path, cut, point_data, cell_data, pool)
            wrote(files)
            return
        write_vtu(mesh, path("mesh.vtu"), point_data=point_data, cell_data=cell_data, leaves=source.leaf_order,
                  pool=pool)
        wrote()
        at = default_cut(source.shapes, self.box) if cut is None else cut
        shapes = ", ".join(source.described.refine or ()) or source.described.file or ""
        cut_png(mesh, path("mesh.png"), at=at,
                title=f"{' x '.join(self.box.texts)}: {shapes}; {report.leaves:,} leaves, {report.elements:,} "
                      f"elements, {report.types} types (cut at z = {at * float(self.box.c):.4g})")
        wrote()
        write_report(report.to_dict(), path("report.json"))
        wrote()

    def _write_tetrahedra(self, path: Callable[[str], Path], gmsh: str | None, binary: bool, tets: bool) -> None:
        """``mesh.msh`` and ``tets.vtu``: the conforming tetrahedral split (:mod:`cospherical.mesh.tetrahedra`)."""
        from ..formats.gmsh import write_msh
        from ..formats.vtu import VTK_CELL, write_grid
        from ..mesh.tetrahedra import simplex_mesh, split_tetrahedra

        mesh = self.assembled
        split = split_tetrahedra(mesh)
        simplices = simplex_mesh(mesh, split, self._result.faces)
        if gmsh is not None:
            write_msh(simplices, path("mesh.msh"), gmsh, binary)
        if tets:
            count = len(split)
            write_grid(path("tets.vtu"), simplices.points, np.full(count, VTK_CELL["tetra"], dtype=np.uint8),
                       split.nodes.reshape(-1), 4 * np.arange(1, count + 1),
                       cell_data={"element": split.parent, "region": split.region})

    def _vtu_data(self, with_dual: bool) -> tuple[dict[str, NDArray[Any]], dict[str, NDArray[Any]]]:
        """The point and cell data ``mesh.vtu`` adds with the dual: control volumes, boundary areas, circumcenters, delaunay_ok."""
        if not with_dual:
            return {}, {}
        dual = self.dual
        point_data: dict[str, NDArray[Any]] = {"control_volume": dual.control_volume,
                                               "boundary_area": dual.boundary_area}
        cell_data: dict[str, NDArray[Any]] = {"circumcenter": dual.element_circumcenter}
        if self.violating is not None:
            ok = np.ones(len(self.assembled), dtype=np.int8)
            ok[self.violating] = 0
            cell_data["delaunay_ok"] = ok
        return point_data, cell_data

    def _device_data(self) -> tuple[dict[str, NDArray[Any]], dict[str, NDArray[Any]]]:
        """A device's cell data ``region`` and field data ``region_names``, ``region_materials`` and ``origin``:
        what ``mesh.vtu`` and :meth:`to_pyvista` hold beyond a one-box mesh's (nothing for a one-box mesh)."""
        from ..formats.vtu import text_array

        mesh, layout = self.assembled, self._result.source.device
        if layout is None or mesh.regions is None:
            return {}, {}
        regions = mesh.regions
        return ({"region": regions.leaf_region[mesh.element_leaf].astype(np.int32)},
                {"region_names": text_array("\n".join(regions.names)),
                 "region_materials": text_array("\n".join(regions.materials)),
                 "origin": text_array(" ".join(str(x) for x in layout.device.origin))})

    def to_pyvista(self) -> Any:  # a pyvista.UnstructuredGrid: the optional library stays out of the checker
        """The mesh as a ``pyvista.UnstructuredGrid``: ``mesh.vtu``'s grid in memory, polyhedra and data included.

        Standard VTK cells where an element is one, ``VTK_POLYHEDRON`` for the others,
        sorted by cell type: cell data ``element`` says which element each cell is,
        ``type`` (into field data ``type_ids``, ``type_names``), ``leaf`` and ``fvm``;
        point data ``grid_coordinates``; once the dual is computed (``dual=True``, or
        ``m.dual`` asked for) also ``control_volume``, ``boundary_area``,
        ``circumcenter`` and ``delaunay_ok``; a device's cell data ``region`` and field data
        ``region_names``, ``region_materials``, ``origin``.  Points are :attr:`vertices` (``origin``
        added).  Needs pyvista: ``pip install 'cospherical[pyvista]'``.
        """
        from ..adapters.pyvista import to_pyvista

        point_data, cell_data = self._vtu_data(self._dual is not None)
        regions, fields = self._device_data()
        return to_pyvista(self.assembled, point_data, {**regions, **cell_data}, self._result.source.leaf_order,
                          self.origin, fields)

    def to_meshio(self) -> Any:  # a meshio.Mesh (meshio has no type information)
        """The mesh split into tetrahedra as a ``meshio.Mesh`` (meshio holds standard cells, not mixed polyhedra).

        Conforming, no new vertex, the exact dual kept (the added edges couple 0):
        :func:`cospherical.mesh.tetrahedra.split_tetrahedra`.  Cell data ``element``
        (the parent element), ``type`` (into :attr:`elements`' ``type_ids``), ``leaf``,
        ``region``.  Write it with ``meshio.write(path, m.to_meshio())``.
        """
        from ..adapters.meshio import to_meshio

        return to_meshio(self.assembled, self.vertices, self._result.source.leaf_order)

    def _write_device(self, path: Callable[[str], Path], cut: float | None, point_data: dict[str, NDArray[Any]],
                      cell_data: dict[str, NDArray[Any]], pool: Executor | None = None) -> None:
        """A device's files: ``mesh.vtu`` with cell data ``region`` (names and materials in field data),
        ``contacts.vtu`` (its contact and interface faces, when it has any), ``mesh.png`` coloured by region, ``report.json``."""
        from ..formats.mesh import write_faces_vtu, write_report, write_vtu
        from ..outputs.mesh_picture import cut_png

        mesh, report, layout = self.assembled, self.report, self._result.source.device
        regions, faces = mesh.regions, self._result.faces
        if layout is None or regions is None or faces is None:
            raise ValueError("_write_device: not a device's mesh (no layout, regions or faces)")
        device = layout.device
        region_cells, fields = self._device_data()
        write_vtu(mesh, path("mesh.vtu"), point_data=point_data, cell_data={**region_cells, **cell_data},
                  field_data=fields, origin=device.origin, pool=pool)
        if device.has_faces:
            write_faces_vtu(mesh, faces, path("contacts.vtu"), origin=device.origin)
        axis = device_cut_axis(device)
        at = 0.5 if cut is None else cut
        low, high = device.bounds[axis]
        cut_png(mesh, path("mesh.png"), at=at, axis=axis, by_region=True,
                title=f"{device.name}: {len(regions.names)} region{'' if len(regions.names) == 1 else 's'}, {report.leaves:,} leaves, "
                      f"{report.elements:,} elements (cut at {'xyz'[axis]} = {float(low + (high - low) * at):.4g})")
        write_report(report.to_dict(), path("report.json"))


def device_cut_axis(device: Device) -> int:
    """The axis ``mesh.png`` cuts a device across: the one its region boxes cut least (y first, then x, then z)."""
    counts = [len({b[a] for r in device.regions for b in r.boxes} | {b[a + 3] for r in device.regions
                                                                     for b in r.boxes}) for a in range(3)]
    return min((1, 0, 2), key=lambda a: counts[a])


def build_mesh(domain: Sequence[Any] | Box | None = None, levels: int | None = None,
               refine: Sequence[str | Shape] | str | None = None, *,
               leaves: str | Path | Sequence[Sequence[int]] | np.ndarray | None = None, tree: Octree | None = None,
               patterns: PatternSource | None = None, criterion: str = "optimal", delaunay: str | None = None,
               balance: str | None = None, dual: bool = False, tetrahedral_counts: bool = False,
               device: str | Path | Device | None = None, max_leaves: int | None = None,
               check_delaunay: bool = True, uniform: bool = True, progress: Progress | None = None,
               checks: str = "default") -> OctreeMesh:
    """Mesh an octree: each leaf's elements, globally Delaunay, checked exactly, reported; the dual on request.

    Parameters
    ----------
    domain
        The root cell's three lengths, exact: ints, or strings such as ``"1.4142"``,
        ``"3/2"``, ``"sqrt(2)"`` (floats are refused: give the text), or a
        :class:`~cospherical.Box`.  Not needed with ``tree`` (the tree has its box).
    levels, refine
        Split every cell whose closed box meets a shape down to ``levels``:
        ``sphere:X,Y,Z,R`` (its surface), ``plane:NX,NY,NZ,D``, ``point:X,Y,Z``,
        ``box:X0,Y0,Z0,X1,Y1,Z1`` in domain units; then 2:1 ``balance`` (``vertex``,
        the default: across faces, edges and corners, or ``edge``; a device file gives its own).
    leaves
        Instead: a leaf list file, or its rows ``(level, i, j, k)``; checked to tile
        the domain and be 1-irregular.  The mesh numbers the leaves as listed.
    tree
        Instead: an :class:`~cospherical.mesh.octree.Octree` already built.
    patterns
        A pattern table of the domain's box (a path, or a table
        :func:`cospherical.load_patterns` read); configurations it lacks, and all
        of them without it, are tessellated.
    criterion
        ``optimal`` (largest co-spherical elements), ``internal_faces`` or ``internal_edges_and_faces``.
    delaunay
        ``global`` (default with ``optimal``: the exact Delaunay subdivision of the
        vertices) or ``leaf`` (default with a split criterion: each leaf's elements).
    dual
        Compute the exact dual now: the report gets its figures and :meth:`OctreeMesh.write`
        writes ``dual.npz`` (otherwise ``m.dual`` computes it on first use).
    tetrahedral_counts
        With ``dual``: the report's dual figures also count a tetrahedral Delaunay mesh of
        the same vertices (TetGen's, else Qhull's; elements, edges, faces, nonzeros) beside
        the mixed mesh: the paper's comparison.  An outside mesher's run, which costs more
        than the dual itself (about 8 CPU-s at 450,000 vertices); skipped above
        :data:`~cospherical.mesh.dual.TETRAHEDRAL_LIMIT` vertices.
    device
        Instead of a domain and a tree: a device (a device file's path, or a
        :class:`~cospherical.mesh.device.Device`): regions of boxes, contacts and
        refinement shapes (:mod:`cospherical.formats.device_file`).  The tree covers
        its bounding box; each element lies in one region.
    max_leaves
        Refuse a tree of more leaves (default: what half this machine's memory holds).
    check_delaunay, uniform
        Run the global empty-sphere check; add the uniform bisection study to the report (read
        from the package for the shapes of the shipped tables, else run: 0.2-0.8 s).
    progress
        ``progress(stage, total, advance)`` as long stages go (see :mod:`cospherical.mesh.pipeline`).
    checks
        ``"all"``: the Delaunay check searches the vertices near every element's sphere,
        none bounded by the tree's structure (a cross-check; the report's ``checks`` says
        which ran and how), each table entry used is checked under every criterion of the
        table (by default only ``criterion``'s elements, the ones that reach the mesh, and none
        of a committed table's, proven by its bytes' digest: see
        :func:`~cospherical.formats.mesh.checked_table`), and the
        uniform study is run even for a box whose figures ship with the package
        (:func:`~cospherical.mesh.statistics.uniform_study`); ``"default"``: bounded where the
        tree allows.

    Examples
    --------
    >>> m = build_mesh(domain=(1, 2, 4), levels=2, refine=["sphere:0.5,1,2,0.3"], uniform=False)
    >>> m.report.leaves, m.report.volume_ok, m.report.nonconforming_faces, m.report.delaunay_violations
    (64, True, 0, 0)
    """
    _check_keywords(domain=domain, refine=refine, tree=tree, patterns=patterns, criterion=criterion,
                    delaunay=delaunay, dual=dual, tetrahedral_counts=tetrahedral_counts, device=device,
                    max_leaves=max_leaves, check_delaunay=check_delaunay, uniform=uniform, progress=progress,
                    checks=checks)
    if device is not None:
        given = [name for name, value in (("domain", domain), ("levels", levels), ("refine", refine),
                                          ("leaves", leaves), ("tree", tree), ("balance", balance))
                 if value is not None]
        if given:
            raise InputError(f"device=: its file gives the domain and the tree, not {given[0]}=")
    else:
        box = _domain_box(domain, tree)
    delaunay_mode(criterion, delaunay)  # a contradiction refused before the work
    if tetrahedral_counts and not dual:
        raise InputError("tetrahedral_counts=True counts beside the dual's figures: give dual=True too")
    clock = time.perf_counter()
    if device is not None:
        from ..mesh.device import Device

        if not isinstance(device, Device):
            from ..formats.device_file import read_device

            device = read_device(device)
        source = tree_from_device(device, max_leaves)
        layout = source.device
        if layout is None:
            raise ValueError("tree_from_device gave no device layout")
        origin: Sequence[Rational | float] = layout.device.origin  # the checked device's (exact coordinates)
    else:
        source = tree_source(box, levels, refine, leaves=leaves, tree=tree, balance=balance or "vertex",
                             max_leaves=max_leaves)
        origin = (0.0, 0.0, 0.0)
    timings = {"tree": time.perf_counter() - clock}
    clock = time.perf_counter()
    lookup, name, proven = _pattern_lookup(patterns, criterion, source.tree.box, every_criterion=checks == "all")
    if patterns is not None:
        timings["table"] = time.perf_counter() - clock
    return OctreeMesh(run_pipeline(source, lookup, patterns=name, criterion=criterion, delaunay=delaunay,
                                   check_delaunay=check_delaunay, uniform=uniform, dual=dual,
                                   tetrahedral_counts=tetrahedral_counts, progress=progress, timings=timings,
                                   checks=checks, entries_proven=proven), origin)


def _domain_box(domain: Sequence[Any] | Box | None, tree: Octree | None) -> Box:
    """The root cell of ``build_mesh(domain=..., tree=...)``: the domain given, else the tree's; the two must agree."""
    if isinstance(domain, Box):
        box = domain
    elif domain is not None:
        if isinstance(domain, str) or len(domain) != 3:
            raise InputError(f"domain={domain!r}: three lengths, such as (1, 2, 4)")
        box = Box.parse(list(domain))
    elif tree is not None:
        box = tree.box
    else:
        raise InputError("domain=: the root cell's three lengths, such as (1, 2, 4)")
    if tree is not None and tree.box != box:
        raise InputError(f"tree=: its domain {' x '.join(tree.box.texts)} is not domain= {' x '.join(box.texts)}")
    return box


def _check_keywords(**given: Any) -> None:
    """:func:`build_mesh`'s keywords of a type it cannot use, refused with one :class:`InputError` naming the
    keyword (a value of the right type is checked where it is used)."""
    from ..choices import CRITERIA
    from ..formats.patterns import PatternTable

    def device(value: Any) -> bool:  # a device's module imported only to tell a Device given
        if path_like(value):
            return True
        from ..mesh.device import Device

        return isinstance(value, Device)

    def path_like(value: Any) -> bool:
        return isinstance(value, (str, Path)) and str(value).strip() != ""

    def flag(value: Any) -> bool:
        return isinstance(value, (bool, np.bool_))

    rules: dict[str, tuple[Callable[[Any], bool], str]] = {
        "domain": (lambda v: isinstance(v, Box) or (hasattr(v, "__len__") and not isinstance(v, (str, bytes))),
                   "three lengths, such as (1, 2, 4), or a Box"),
        # a set would be taken in hash order: the report's list of shapes would change from run to run
        "refine": (lambda v: isinstance(v, (str, Shape, list, tuple)),
                   "a shape or a list of shapes, such as ['sphere:0.5,0.5,0.5,0.3']"),
        "tree": (lambda v: isinstance(v, Octree), "an Octree (cospherical.mesh.octree)"),
        "patterns": (lambda v: isinstance(v, PatternTable) or path_like(v),
                     "a pattern table's path, or a table cospherical.load_patterns read"),
        "criterion": (lambda v: isinstance(v, str) and v in CRITERIA, f"one of {', '.join(CRITERIA)}"),
        "delaunay": (lambda v: isinstance(v, str), "global or leaf"),
        "device": (device, "a device file's path, or a Device"),
        "max_leaves": (lambda v: isinstance(v, (int, np.integer)) and not isinstance(v, bool) and bool(v >= 1),
                       "a positive integer"),
        "progress": (callable, "a callable progress(stage, total, advance)"),
        "checks": (lambda v: v in ("default", "all"), "default or all"),
        "dual": (flag, "True or False"), "check_delaunay": (flag, "True or False"), "uniform": (flag, "True or False"),
        "tetrahedral_counts": (flag, "True or False"),
    }
    for name, value in given.items():
        fits, wanted = rules[name]
        if value is not None and not fits(value) or value is None and name in ("criterion", "dual", "check_delaunay",
                                                                                  "uniform", "tetrahedral_counts",
                                                                                  "checks"):
            raise InputError(f"{name}={shown(value)}: {wanted}")


def from_treemesh(tree_mesh: Any, **options: Any) -> OctreeMesh:
    """Mesh a ``discretize.TreeMesh`` (3-D, built with ``diagonal_balance=True``): its cells are the leaves.

    The domain is the TreeMesh's (its sides as decimals, its ``origin`` kept in
    :attr:`OctreeMesh.vertices`); the vertices are every leaf corner, hanging nodes
    included: discretize's ``total_nodes``.  ``options`` are :func:`build_mesh`'s
    (``patterns``, ``dual``, ``criterion``, ...); the mesh numbers the leaves as
    discretize numbers its cells (cell data ``leaf``, :attr:`Elements.leaf`).

    Examples
    --------
    >>> import discretize
    >>> tree_mesh = discretize.TreeMesh([[(1 / 4, 4)]] * 3, diagonal_balance=True)
    >>> tree_mesh.refine_points([[0.3, 0.6, 0.7]], level=2)
    >>> m = from_treemesh(tree_mesh, uniform=False)
    >>> len(m.vertices) == tree_mesh.n_total_nodes, m.report.volume_ok
    (True, True)
    """
    from ..adapters.discretize import treemesh_leaves

    for taken in ("domain", "levels", "refine", "leaves", "tree", "device", "balance"):
        if taken in options:
            raise InputError(f"from_treemesh: {taken}= is the TreeMesh's own")
    leaves = treemesh_leaves(tree_mesh)
    rows = np.column_stack([leaves.levels, leaves.positions])
    try:
        mesh = build_mesh(domain=leaves.lengths, leaves=rows, **options)
    except InputError as error:
        if "1-irregular" not in str(error):
            raise
        # discretize balances across faces only unless asked: the one fix a TreeMesh user needs
        raise InputError(f"{error}: build the TreeMesh with diagonal_balance=True") from None
    return OctreeMesh(mesh._result, leaves.origin)


if TYPE_CHECKING:
    def _devsim_takes(mesh: OctreeMesh) -> MeshWithDual:
        """The type checker proves that create_device takes the API's mesh (its Protocol, below the API)."""
        return mesh
