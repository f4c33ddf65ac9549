"""An octree meshed in pieces: subtrees as separate tasks, on a local process pool or a Dask cluster.

The leaves are cut into ``N`` runs of the Morton (Z-order) curve, as equal in
leaves as can be: each run is a union of whole subtrees.  A task meshes one piece
(:func:`mesh_piece`), checks it exactly and writes it; this process adds the
pieces' figures up into the report of the whole mesh, pairs the faces the pieces
left open at their seams, and re-tessellates the regions of the global Delaunay
subdivision.

Why a piece is the whole mesh's restriction, element for element:

- **Vertices and their ids.**  Every task is given the vertex keys of the whole
  tree (:func:`~cospherical.mesh.assembly.vertex_keys`: every leaf corner, an
  integer grid point).  A leaf's configuration is which of its 27 slots are
  vertices, so a piece's leaves get the configurations, elements and vertex ids
  they have in the whole tree; a vertex's id is its rank among the keys, the same
  in every piece and in the mesh of one process (the ``global_id`` of the files).
- **Conformity at the seams.**  A piece's faces met once off the domain's boundary
  are paired across pieces (:func:`~cospherical.mesh.checks.match_seams`, which
  says why the counts are the whole mesh's).
- **Empty spheres at the seams.**  A piece checks its elements against every
  vertex of the whole tree that can be within reach of one of its spheres (the
  search is limited to the box around all of them, see
  :func:`~cospherical.mesh.checks.check_delaunay`): an element's sphere is decided
  against exactly the vertices it would be in one process.
- **Global Delaunay.**  In ``global`` mode a first round of tasks assembles and
  checks the leaf mesh; the leaves holding an element that is not a cell of the
  Delaunay subdivision (any piece's) are re-tessellated here, region by region,
  exactly as in one process (:func:`~cospherical.mesh.delaunay.retessellate` on
  the marked leaves alone, told which of their elements failed, with the whole
  tree's vertices: its proof holds for
  regions that cross seams, since nothing in it depends on the pieces).  Each new
  cell goes to the piece that holds its first leaf (the leaf holding an interior
  point of it, a marked one), and those pieces are meshed again with their cells,
  checked and written.  Pieces with no marked leaf are checked and written in the
  first round: no cell can go to them.  Cube octrees have no marked leaf.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, replace
from typing import Any, TypeVar

import numpy as np
from numpy.typing import NDArray

from ..catalogue import Catalogue, shipped_catalogue
from ..core.configuration import Box
from ..core.morton import morton_codes
from ..errors import InputError
from ..execution.backends import completed
from .assembly import Cells, MeshType, assemble, vertex_keys
from .checks import OpenFaces, check_delaunay
from .delaunay import retessellate, with_cells
from .octree import Octree, distinct
from .report import MeshReport, PieceFigures, merged_report, mesh_figures
from .report_sections import LeafMeshSummary, TreeSummary

__all__ = ["MAX_PARTITIONS", "Piece", "PieceResult", "mesh_in_pieces", "mesh_piece", "morton_pieces"]

# The pattern lookup as it travels to a worker (a closure does not): a factory and its arguments.
LookupRecipe = tuple[Callable[..., Any], tuple[Any, ...]]
T = TypeVar("T")

# More pieces than this is a mistake, not a plan: one file each, in one folder.
MAX_PARTITIONS = 4096


def morton_pieces(tree: Octree, pieces: int) -> list[np.ndarray]:
    """The leaves (indices, increasing) of ``pieces`` runs of the Morton curve, as equal in leaves as can be.

    Examples
    --------
    >>> from cospherical.mesh.octree import build_octree, parse_shape
    >>> tree = build_octree(Box.parse([1, 1, 1]), 1, [parse_shape("point:0.5,0.5,0.5")])
    >>> [part.tolist() for part in morton_pieces(tree, 3)]
    [[0, 1], [2, 3, 4], [5, 6, 7]]
    """
    if not 1 <= pieces <= len(tree):
        raise InputError(f"--partitions {pieces}: from 1 to the tree's {len(tree):,} leaves")
    depth = tree.depth
    corner = tree.positions.astype(np.int64) << (depth - tree.levels.astype(np.int64))[:, None]
    order = np.argsort(morton_codes(corner), kind="stable")
    bounds = [len(tree) * k // pieces for k in range(pieces + 1)]
    return [np.sort(order[bounds[k]:bounds[k + 1]]) for k in range(pieces)]


@dataclass(frozen=True)
class Piece:
    """One task: a piece's leaves, what it needs of the whole tree, and where it writes.

    ``leaves`` are the piece's leaf indices in the whole tree; ``grid`` the whole
    tree's vertex grid; ``write(mesh, path, leaves)`` writes the piece (a module-level
    function) to ``path``.  What every piece shares, the vertex keys and the lookup,
    travels beside it (see :func:`mesh_piece`).  ``cells`` (their
    ``leaf`` indexing the piece's leaves), ``replaced`` (a mask over them) and
    ``types`` come with the second round of ``global`` mode.
    """

    index: int
    box: Box
    levels: np.ndarray
    positions: np.ndarray
    leaves: np.ndarray
    grid: int
    criterion: str
    mode: str
    delaunay: bool
    write: Callable[..., None] | None
    path: str | None
    cells: Cells | None = None
    replaced: np.ndarray | None = None
    types: dict[str, MeshType] | None = None
    vertex_balanced: bool = False  # the whole tree's (Octree.vertex_balanced): the piece's vertices are its


@dataclass(frozen=True)
class PieceResult:
    """What a task found on its piece (:func:`mesh_piece`).

    Attributes
    ----------
    index : int
        The piece's number.
    leaf_mesh : LeafMeshSummary or None
        In the first round of ``global`` mode: what the exact check found on the piece's leaf mesh.
    marked : ndarray or None
        Then, if some of its elements are not cells of the Delaunay subdivision: those
        leaves (whole-tree indices); the piece is not meshed further in this round.
    failing : tuple of two ndarrays or None
        With ``marked``: those elements, as (whole-tree leaf, index in the leaf).
    figures : PieceFigures or None
        Else the piece's figures (:func:`~cospherical.mesh.report.mesh_figures`), which add up.
    seams : tuple of OpenFaces
        With ``figures``: the faces it leaves open at its seams.
    """

    index: int
    leaf_mesh: LeafMeshSummary | None = None
    marked: NDArray[np.integer[Any]] | None = None
    failing: tuple[NDArray[np.integer[Any]], NDArray[np.integer[Any]]] | None = None
    figures: PieceFigures | None = None
    seams: tuple[OpenFaces, ...] = ()


def mesh_piece(piece: Piece, keys: np.ndarray, lookup: LookupRecipe | None, catalogue: Catalogue) -> PieceResult:
    """Mesh, check and write one piece (run in a worker); see the module for why it equals its part of the whole.

    ``keys``: the whole tree's vertex keys; ``lookup``: ``(factory, arguments)`` that make
    the pattern lookup in the worker (a closure does not travel), or ``None``.  Both are
    the same for every piece: on Dask they reach each worker once; so does ``catalogue``,
    the element catalogue every piece is assembled with.

    Returns a :class:`PieceResult`: in the first round of ``global`` mode ``leaf_mesh`` and, if
    some of its elements are not cells of the Delaunay subdivision, ``marked`` and ``failing``
    and nothing more; else ``figures`` and ``seams``.
    """
    tree = Octree(piece.box, piece.levels, piece.positions, piece.vertex_balanced)
    mesh = assemble(tree, lookup[0](*lookup[1]) if lookup is not None else None, criterion=piece.criterion,
                    vertices=(piece.grid, keys), catalogue=catalogue)
    leaf_mesh = None
    checked = None
    if piece.cells is not None:
        replaced = piece.replaced if piece.replaced is not None else np.zeros(len(tree), dtype=bool)
        mesh = with_cells(mesh, replaced, piece.cells, {**mesh.types, **(piece.types or {})})
    elif piece.mode == "global":
        found = check_delaunay(mesh)
        leaf_mesh = found.leaf_mesh(len(mesh))
        failing = found.not_cells
        if len(failing):
            return PieceResult(piece.index, leaf_mesh, piece.leaves[distinct(mesh.element_leaf[failing])],
                               (piece.leaves[mesh.element_leaf[failing]], mesh.element_local[failing]))
        checked = found
    figures, _, open_faces = mesh_figures(mesh, piece.delaunay, checked=checked, open_faces=True)
    if piece.write is not None:
        piece.write(mesh, piece.path, piece.leaves)
    return PieceResult(piece.index, leaf_mesh, figures=figures, seams=open_faces)


def mesh_in_pieces(tree: Octree, pieces: int, lookup: LookupRecipe | None, criterion: str, mode: str,
                   described: TreeSummary, patterns: str | None, uniform: bool = True, delaunay: bool = True,
                   write: Callable[..., None] | None = None, path: Callable[[int], str] | None = None, jobs: int = 1,
                   scheduler: str | None = None, dask_workers: int | None = None, catalogue: Catalogue | None = None,
                   progress: Callable[[str, int, int], None] | None = None) -> MeshReport:
    """Mesh ``tree`` in ``pieces`` tasks (each writing ``path(k)`` with ``write``); return the whole mesh's report.

    ``lookup``: ``(factory, arguments)`` of the pattern lookup (``None``: every
    configuration tessellated); ``jobs``, ``scheduler``, ``dask_workers``: where the
    tasks run (:func:`~cospherical.execution.backends.completed`); ``catalogue``: the
    element catalogue (default: the shipped one), as in :func:`~cospherical.mesh.assembly.assemble`.
    ``progress(stage, total, n)``: told as the pieces finish, on whichever backend, ``n`` more of
    ``total``; stage ``pieces`` (every piece, told with 0 when they start) and ``again`` (the
    pieces whose leaves are re-tessellated across the seams, a second round).
    """
    catalogue = shipped_catalogue() if catalogue is None else catalogue
    grid, keys = vertex_keys(tree)
    parts = morton_pieces(tree, pieces)

    def task(k: int, **more: Any) -> tuple[Piece]:
        leaves = parts[k]
        return (Piece(k, tree.box, tree.levels[leaves], tree.positions[leaves], leaves, grid, criterion, mode,
                      delaunay, write, path(k) if path is not None else None, **more,
                      vertex_balanced=tree.vertex_balanced),)

    def told(stage: str, total: int, finished: Iterable[T]) -> Iterator[T]:
        if progress is not None:
            progress(stage, total, 0)
        for item in finished:
            if progress is not None:
                progress(stage, total, 1)
            yield item

    results: dict[int, PieceResult] = dict(told("pieces", pieces, completed(mesh_piece, {k: task(k) for k in range(pieces)}, jobs, scheduler,
                                                    dask_workers, common=(keys, lookup, catalogue))))
    leaf_mesh = None
    regions = (0, 0)
    if mode == "global":
        leaf_meshes = [f for f in (results[k].leaf_mesh for k in range(pieces)) if f is not None]  # every piece's
        leaf_mesh = sum(leaf_meshes[1:], leaf_meshes[0])
        marked = np.sort(np.concatenate([_marked(results[k]) for k in range(pieces)]))
        if len(marked):
            found = [f for f in (results[k].failing for k in range(pieces)) if f is not None]
            failing = (np.concatenate([f[0] for f in found]), np.concatenate([f[1] for f in found]))
            again, regions = _cells_by_piece(tree, parts, marked, failing, grid, keys, lookup, criterion,
                                                     catalogue)
            results.update(told("again", len(again), completed(
                mesh_piece, {k: task(k, **more) for k, more in again.items()}, jobs, scheduler, dask_workers,
                common=(keys, lookup, catalogue))))
            # As in one process, the spheres counted are those of the final check, the fresh cells': the leaf
            # elements kept were proven by the leaf mesh's check, whose spheres the one process does not count
            for k in set(range(pieces)) - set(again):
                results[k] = replace(results[k], figures=replace(_figures(results[k]), delaunay_spheres_bounded=0))
    seams = [seam for k in range(pieces) for seam in results[k].seams]
    n = np.int64(grid + 1)

    def points(ids: np.ndarray) -> np.ndarray:
        return np.stack([keys[ids] // (n * n), (keys[ids] // n) % n, keys[ids] % n], axis=-1)

    return merged_report(tree, len(keys), [_figures(results[k]) for k in range(pieces)], described, patterns,
                         criterion, uniform, delaunay, leaf_mesh, regions, seams, points, grid, catalogue=catalogue)


def _marked(result: PieceResult) -> NDArray[np.integer[Any]]:
    """A piece's leaves marked for re-tessellation (none when it holds only Delaunay cells)."""
    return result.marked if result.marked is not None else np.zeros(0, dtype=np.int64)


def _figures(result: PieceResult) -> PieceFigures:
    """A piece's figures, which every piece has once meshed (the first round's marked pieces are meshed again)."""
    if result.figures is None:
        raise ValueError(f"mesh_in_pieces: piece {result.index} was not meshed")
    return result.figures


def _cells_by_piece(tree: Octree, parts: list[np.ndarray], marked: np.ndarray,
                    failing: tuple[np.ndarray, np.ndarray], grid: int,
                    keys: np.ndarray, lookup: LookupRecipe | None, criterion: str,
                    catalogue: Catalogue) -> tuple[dict[int, dict[str, Any]], tuple[int, int]]:
    """Re-tessellate the marked leaves (whole-tree indices) and give each cell to the piece of its first leaf.

    ``failing``: the elements that are not Delaunay cells, as (whole-tree leaf, index in the leaf).

    Returns, per piece with marked leaves, its second round's ``cells``, ``replaced``
    and ``types``, and (regions, the largest region's vertices).
    """
    sub = Octree(tree.box, tree.levels[marked], tree.positions[marked])
    mesh = assemble(sub, lookup[0](*lookup[1]) if lookup is not None else None, criterion=criterion,
                    vertices=(grid, keys), catalogue=catalogue)
    types = dict(mesh.types)
    cells, _ = retessellate(mesh, mesh.element_offsets[np.searchsorted(marked, failing[0])] + failing[1], types)
    piece_of_leaf = np.empty(len(tree), dtype=np.int64)
    for k, leaves in enumerate(parts):
        piece_of_leaf[leaves] = k
    first = marked[cells.leaf]  # whole-tree leaves
    again = {}
    for k in np.unique(piece_of_leaf[marked]).tolist():
        rows = np.flatnonzero(piece_of_leaf[first] == k)
        used, shape = np.unique(cells.shape[rows], return_inverse=True)
        mine = Cells([cells.shapes[s] for s in used.tolist()], shape.astype(np.int32).reshape(-1),
                     cells.anchor[rows], cells.nodes[rows], np.searchsorted(parts[k], first[rows]),
                     cells.spanning[rows], cells.proven[rows], cells.clusters, cells.largest_cluster)
        replaced = np.isin(parts[k], marked)
        again[k] = {"cells": mine, "replaced": replaced, "types": types}
    return again, (cells.clusters, cells.largest_cluster)
