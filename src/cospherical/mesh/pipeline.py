"""The one mesh pipeline: an octree in, the mesh, its exact checks, its report and (on request) its dual out.

Every way of making a mesh of a whole tree goes through here, the library's
:func:`cospherical.build_mesh` and the command ``cospherical mesh`` alike, so the two
cannot drift apart::

    tree (refine shapes | a leaf list | an Octree)      -> TreeSource
      -> assembly (each leaf's elements: table lookup, else tessellated)
      -> global Delaunay (the leaves whose elements are not Delaunay, re-tessellated)
      -> checks (volume, conformity, circumcenters, empty spheres) and statistics
      -> report (MeshReport) and, with ``dual=True``, the exact dual

Reading files (a pattern table, a leaf list) and writing them are the formats' job,
one layer up: :func:`run_pipeline` takes the table's ``lookup`` already made, and
the caller writes what it returns.  ``progress(stage, total, advance)`` is told as a
long stage goes (``assembly`` through the leaves, ``regions`` through the leaf
mesh's elements in the global Delaunay step, ``delaunay`` through the elements in
the final check, ``conformity`` through the faces paired, ``dual`` once done), ``total``
the stage's size (``None``: not known before), so a command line can draw a bar per
stage and a library user can pass nothing.

Examples
--------
>>> from cospherical.core.configuration import Box
>>> source = tree_from_refine(Box.parse([1, 1, 1]), 2, ["point:0.1,0.1,0.1"])
>>> result = run_pipeline(source, uniform=False)
>>> result.report.leaves, result.report.elements, result.report.volume_ok, result.report.delaunay_violations
(15, 48, True, 0)
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from ..core.configuration import Box
from ..errors import InputError
from .assembly import Lookup, Mesh, assemble
from ..choices import MODES, DelaunayMode
from .delaunay import delaunay_mesh
from .octree import Octree, Shape, build_octree, leaf_list_order, leaves_octree, parse_shape
from .report import MeshReport, checked_mesh_report
from .report_sections import TreeSummary

if TYPE_CHECKING:  # the dual's and a device's modules are imported when they are asked for
    from .device import Device, DeviceLayout
    from .dual import Dual
    from .regions import RegionFaces

__all__ = ["PipelineResult", "Progress", "TreeSource", "delaunay_mode", "full_dual", "run_pipeline", "tree_from_device",
           "tree_from_leaves", "tree_from_octree", "tree_from_refine"]

Progress = Callable[[str, "int | None", int], None]
"""``progress(stage, total, advance)``: ``advance`` more items of ``stage`` done, out of ``total``."""


@dataclass(frozen=True)
class TreeSource:
    """The octree to mesh and where it came from.

    ``described`` is the report's ``tree`` section (``source``: ``refine``, ``leaves``
    or ``device``, with the levels, shapes and balance, or the leaf file's name, and
    the depth); ``leaf_order`` numbers the leaves as the user listed them (the
    ``leaf`` cell data of ``mesh.vtu``), ``None`` for the tree's own order;
    ``shapes`` the refinement shapes (the picture cuts through the first one);
    ``device`` a device's layout and ``leaf_region`` each leaf's region (a device's
    tree, :func:`tree_from_device`), else ``None``.
    """

    tree: Octree
    described: TreeSummary
    leaf_order: NDArray[np.int64] | None = None
    shapes: tuple[Shape, ...] = ()
    device: DeviceLayout | None = None
    leaf_region: NDArray[np.integer[Any]] | None = None


def tree_from_refine(box: Box, levels: int, refine: Sequence[str | Shape], balance: str = "vertex",
                     max_leaves: int | None = None) -> TreeSource:
    """The tree refined at ``refine`` (shape texts such as ``sphere:0.5,0.5,0.5,0.3``, or :class:`Shape`) down to ``levels``."""
    shapes = tuple(s if isinstance(s, Shape) else parse_shape(s) for s in refine)
    tree = build_octree(box, levels, shapes, balance, max_leaves)
    return TreeSource(tree, TreeSummary("refine", levels=levels, refine=tuple(s.text for s in shapes),
                                        balance=balance, depth=tree.depth), None, shapes)


def tree_from_leaves(box: Box, levels: Sequence[int] | np.ndarray, positions: Sequence[Sequence[int]] | np.ndarray,
                     where: str = "leaves", file: str | None = None) -> TreeSource:
    """The tree of a leaf list (``levels[i]``, ``positions[i]``), checked to tile the domain and be 1-irregular.

    The mesh numbers the leaves as the list does; ``file`` (the list's file name) goes in the report.
    """
    tree = leaves_octree(box, levels, positions, where=where)
    return TreeSource(tree, TreeSummary("leaves", file=file, depth=tree.depth), leaf_list_order(levels, positions))


def tree_from_device(device: Device, max_leaves: int | None = None) -> TreeSource:
    """The tree of a device (:mod:`cospherical.mesh.device`): checked, refined until its region boundaries and
    contact edges lie on leaf faces, balanced, the leaves outside every region dropped."""
    from .device import device_layout, device_octree

    try:
        layout = device_layout(device)
        device = layout.device  # checked: exact coordinates, shapes parsed
        tree, leaf_region = device_octree(layout, max_leaves)
        _coordinates_fit_floats(device, tree.depth)
    except InputError as error:
        if device.source is None:
            raise
        # what is found past a file's parsing names the file too, as its parse errors do
        raise InputError(f"{device.source}: {error}") from None
    described = TreeSummary("device", device=device.name, levels=device.levels,
                            refine=tuple(s.text for s in device.refine), balance=device.balance,
                            resolving_level=layout.resolving_level, depth=tree.depth)
    return TreeSource(tree, described, None, device.refine, layout, leaf_region)


# The files' coordinates (mesh.vtu, mesh.msh, tets.vtu, what DEVSIM reads) keep at least this share of the
# smallest leaf's side: half of float64's 53 bits. A device at the origin keeps 36 or more at 16 levels.
_FLOAT_BITS_KEPT = 26


def _coordinates_fit_floats(device: Device, depth: int) -> None:
    """Refuse, in one line, a device whose float coordinates cannot tell its smallest leaves apart.

    The exact mesh and dual do not depend on where a device lies, but every file a solver
    reads holds float64 coordinates ``origin + x``: a device 1e20 from the origin had its
    vertices rounded onto one another (cells of volume 0 in VTK) and a 1e-3 cube at 1e12 had
    its volumes 2 % off, both written without a word.
    """
    for axis, (low, high) in enumerate(device.bounds):
        reach = float(max(abs(low), abs(high)))
        step = float((high - low) / (1 << depth))
        spacing = math.ulp(reach)
        if spacing > math.ldexp(step, -_FLOAT_BITS_KEPT):
            raise InputError(f"device {device.name!r}: its coordinates reach {reach:.6g} along {'xyz'[axis]}, where "
                             f"float64 coordinates (those of the files) are {spacing:.3g} apart: too coarse for its "
                             f"smallest leaves ({step:.3g} wide; at most 2**-{_FLOAT_BITS_KEPT} of them): move the "
                             "device nearer the origin (its exact mesh and dual do not depend on where it lies)")


def tree_from_octree(tree: Octree) -> TreeSource:
    """A tree already built (by :func:`~cospherical.mesh.octree.build_octree` or :func:`~cospherical.mesh.octree.leaves_octree`).

    Its :attr:`~cospherical.mesh.octree.Octree.vertex_balanced` claim, on which the Delaunay
    check's bound rests, is kept only where the leaves bear it out: a tree from a caller may
    have been edited (``dataclasses.replace`` keeps the flag) or built by hand.
    """
    if tree.vertex_balanced and not _balanced_at_corners(tree):
        tree = replace(tree, vertex_balanced=False)
    return TreeSource(tree, TreeSummary("leaves", depth=tree.depth))


def _balanced_at_corners(tree: Octree) -> bool:
    """Whether every cell touching a split cell across a face, an edge or a corner exists (its parent is split):
    leaves touching anywhere are then at most one level apart, as ``build_octree(balance="vertex")`` makes them."""
    from .tree import cells_of, distinct, keys_of, neighbour_offsets, neighbours

    levels = tree.levels.astype(np.int64)
    positions = tree.positions.astype(np.int64)
    offsets = neighbour_offsets("vertex")
    split = [distinct(np.concatenate([keys_of(level, positions[levels == deeper] >> (deeper - level))
                                      for deeper in range(level + 1, tree.depth + 1)]))
             for level in range(tree.depth)]
    for level in range(1, tree.depth):
        need = neighbours(level, cells_of(level, split[level]), offsets)
        if not np.isin(keys_of(level - 1, cells_of(level, need) // 2), split[level - 1]).all():
            return False
    return True


def delaunay_mode(criterion: str, delaunay: str | None) -> DelaunayMode:
    """The Delaunay mode asked for, or the criterion's default (``global`` for ``optimal``, else ``leaf``)."""
    asked = delaunay or ("global" if criterion == "optimal" else "leaf")
    mode = next((known for known in MODES if known == asked), None)
    if mode is None:
        raise InputError(f"--delaunay {asked!r}: write global or leaf")
    if mode == "global" and criterion != "optimal":
        raise InputError(f"--delaunay global gives the largest co-spherical cells, which --criterion "
                         f"{criterion} splits; use --delaunay leaf with it")
    return mode


@dataclass(frozen=True)
class PipelineResult:
    """What :func:`run_pipeline` made: the mesh, its report, its dual (or ``None``) and the non-Delaunay elements.

    ``violating``: the elements whose circumsphere strictly holds a vertex (``None``
    when the check was skipped); ``source``: the tree it meshed; ``faces``: a device's
    contact and interface faces (:class:`~cospherical.mesh.regions.RegionFaces`).
    """

    source: TreeSource
    mesh: Mesh
    report: MeshReport
    dual: Dual | None = field(default=None, repr=False)
    violating: NDArray[np.int64] | None = field(default=None, repr=False)
    faces: RegionFaces | None = field(default=None, repr=False)


class _Clock:
    """Seconds per stage, in the order the stages first ran (a stage entered again adds to its time)."""

    def __init__(self, timings: dict[str, float]) -> None:
        self.timings = timings
        self.current: str | None = None
        self.start = time.perf_counter()

    def stage(self, name: str | None) -> None:
        now = time.perf_counter()
        if self.current is not None:
            self.timings[self.current] = self.timings.get(self.current, 0.0) + now - self.start
        self.current, self.start = name, now


def run_pipeline(source: TreeSource, lookup: Lookup | None = None, *, patterns: str | None = None,
                 criterion: str = "optimal", delaunay: str | None = None, check_delaunay: bool = True,
                 uniform: bool = True, dual: bool = False, tetrahedral_counts: bool = False,
                 progress: Progress | None = None, timings: dict[str, float] | None = None,
                 checks: str = "default", entries_proven: str | None = None) -> PipelineResult:
    """Mesh ``source``'s tree, check it exactly, report it and, with ``dual``, compute its finite-volume dual.

    Parameters
    ----------
    source
        The tree (:func:`tree_from_refine`, :func:`tree_from_leaves`, :func:`tree_from_octree`,
        :func:`tree_from_device`: a device's tree, meshed region by region with its contacts).
    lookup
        A pattern table's elements per configuration
        (:func:`cospherical.formats.mesh.table_lookup`); ``None``: every configuration tessellated.
    patterns
        The table's name, for the report.
    criterion
        ``optimal``, ``internal_faces`` or ``internal_edges_and_faces``: which elements of the table.
    delaunay
        ``global`` (the exact Delaunay subdivision of the vertices) or ``leaf`` (each
        leaf's elements as the table has them); ``None``: the criterion's default
        (:func:`delaunay_mode`).
    check_delaunay
        Run the global empty-sphere check (``False``: ``delaunay_violations`` is ``None``).
    uniform
        Add the uniform-weight bisection study beside the mesh's frequencies.
    dual
        Compute the exact dual now (the report then holds its figures).
    tetrahedral_counts
        With ``dual``: count a tetrahedral Delaunay mesh of the same vertices by an outside
        mesher beside the mixed mesh, in the report's dual figures (``None`` there otherwise).
    progress
        ``progress(stage, total, advance)``, see the module's docstring.
    timings
        Seconds of stages run before (the tree, the table), put first in the report's timings.
    checks
        ``all``: the Delaunay check searches the vertices near every sphere with a k-d tree,
        none bounded by the tree's structure (the cross-check of that bound: see
        :mod:`cospherical.mesh.checks.empty_sphere`), and the uniform study is computed even where its
        figures ship precomputed; ``default``: bounded where the tree allows.
    entries_proven
        Why ``lookup``'s table entries were not held to ``check``'s rules (a committed table's bytes:
        :func:`cospherical.formats.mesh.checked_table`); the report's ``checks`` then lists
        ``table_entries`` as not run, with this reason.
    """
    mode = delaunay_mode(criterion, delaunay)
    if checks not in ("default", "all"):
        raise InputError(f"checks={checks!r}: default or all")
    timings = dict(timings or {})
    clock = _Clock(timings)
    tree = source.tree if checks == "default" else replace(source.tree, vertex_balanced=False)

    def told(stage: str, total: int | None) -> Callable[[int], None] | None:
        return (lambda n: progress(stage, total, n)) if progress is not None else None

    clock.stage("assembly")
    if source.device is not None:
        from .regions import device_mesh

        if source.leaf_region is None:
            raise ValueError("run_pipeline: a device's tree source without its leaves' regions (tree_from_device)")
        mesh, leaf_mesh, checked = device_mesh(source.device, tree, source.leaf_region, lookup, criterion, mode,
                                               progress=progress)
    else:
        mesh = assemble(tree, lookup, progress=told("assembly", len(tree)), criterion=criterion)
        clock.stage("global Delaunay" if mode == "global" else None)
        mesh, leaf_mesh, checked = delaunay_mesh(mesh, mode, progress=told("regions", len(mesh)))
    checked_report = checked_mesh_report(mesh, source.described, patterns, criterion, uniform=uniform,
                                         delaunay=check_delaunay, stage=clock.stage,
                                         progress=told("delaunay", len(mesh)), leaf_mesh=leaf_mesh, checked=checked,
                                         conformity_progress=told("conformity", None),
                                         uniform_computed=checks == "all")
    report = checked_report.report
    if entries_proven is not None and report.checks is not None:
        report = replace(report, checks=report.checks.not_running("table_entries", entries_proven))
    found = faces = None
    if source.device is not None:
        from .regions import device_report, region_faces

        clock.stage("regions")
        faces = region_faces(mesh)
    if dual:
        from .dual import dual_summary

        clock.stage("dual")
        if progress is not None:
            progress("dual", 1, 0)
        found = full_dual(mesh, faces)
        if progress is not None:
            progress("dual", 1, 1)
        figures = dual_summary(found, len(mesh), report.interior_faces + report.boundary_faces,
                               tetrahedral=tetrahedral_counts)
        report = replace(report, negative_coefficients=figures.negative_coefficients, dual=figures.dual)
    if faces is not None:
        clock.stage("regions")
        report = replace(report, device=device_report(mesh, faces, found))
    clock.stage(None)
    return PipelineResult(source, mesh, report.with_timings(timings), found,
                          checked_report.delaunay.violating_elements if checked_report.delaunay is not None else None,
                          faces)


def full_dual(mesh: Mesh, faces: RegionFaces | None, dual: Dual | None = None) -> Dual:
    """The mesh's exact dual (``dual`` when already computed) with, for a device, its parts per region and contact.

    ``faces``: the device's region faces (:attr:`PipelineResult.faces`), ``None`` for a one-box mesh.
    The one place both the pipeline (``dual=True``) and a dual asked for later make it.
    """
    from .dual import mesh_dual

    if dual is None:
        dual = mesh_dual(mesh)
    if faces is not None and dual.regions is None:
        from .regions import device_of, mesh_region_parts
        from .surfaces import interface_parts, set_domain_boundary

        # a union of boxes: its boundary, not the bounding box's
        set_domain_boundary(dual, faces.boundary_nodes, faces.boundary_edges)
        dual.regions = mesh_region_parts(mesh, dual, faces)
        regions, layout, _ = device_of(mesh)
        (x0, x1), (y0, y1), (z0, z1) = layout.device.bounds
        dual.regions.interfaces = interface_parts(
            mesh.vertices, mesh.grid, (x1 - x0, y1 - y0, z1 - z0), regions.names,
            faces.interfaces, faces.interface_nodes, faces.interface_face_interface)
    return dual
