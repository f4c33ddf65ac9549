"""Exact checks of a whole mesh: volume, conformity, circumcenters in their leaf, global Delaunay.

Per-leaf properties (a configuration's volume, its circumcenters) are decided once
per distinct configuration, exactly, and counted over the leaves that have it.
Whole-mesh properties are decided on the global vertex ids (conformity) and on the
global vertex set (Delaunay): a leaf's sphere can hold a vertex of a smaller
neighbour, so no per-leaf test can replace them.

Global Delaunay, exactly: every vertex that could lie on or in an element's sphere
is found, and each is decided with the integer in-sphere test of the element's
configuration frame (the same predicate as the tessellation's), so every violation
and every tie is decided exactly.  Two ways find them:

- By the tree's structure, for the leaf elements of a full tree whose leaves
  touching at a face, an edge or a corner differ by at most one level
  (:attr:`~cospherical.mesh.octree.Octree.vertex_balanced`).  Let B be a leaf of side
  s (per axis) and d the L-infinity distance from B in units of s.  Then the
  vertices with d = 0 are B's slots (the leaves touching B are at least s/2, so
  their corners on B are the 27 half-spacing points, and no vertex is inside a
  leaf); none has 0 < d < 1/2, and those with 1/2 <= d < 3/4 are points of the
  lattice of spacing s/4 aligned with B.  Proof: a vertex is a corner of some leaf
  T; if T is at least s/4 its corners are on that lattice, and at least s/2 puts
  them at d = 0 or d >= 1/2.  A T of side s/4 with a corner at 0 < d < 1/2 has a
  parent cell (side s/2) within d < 1/2 of B, hence touching B, split into leaves
  of at most s/4, one of which touches B: two levels apart.  Otherwise T (at most
  s/8) lies in a cell C of side s/4 of the aligned grid, split, within d <= 1/2 of B.  If C's parent cell (side
  s/2) touches B, that parent is split into leaves of at most s/4, one of which
  touches B: two levels apart.  If not, C touches a cell of side s/2 that touches B,
  and that cell lies in one leaf of at least s/2 (or leaves under s/2 would touch
  B); a leaf in C of at most s/8 touches it: two levels apart again.  So for an
  element whose closed sphere stays within d < 3/4 (decided exactly, once per
  configuration, in the leaf's unit frame: every leaf is the domain scaled), the
  only vertices that can lie on or in it are its leaf's other slots in the sphere
  and the lattice points with d = 1/2 in the sphere that are vertices: a handful
  of exact look-ups per leaf (:func:`_local_candidates`), no search.  The proof
  reads only the whole tree's structure: a part of its leaves (a device keeps those
  inside its boxes, a region's mesh those of the region) has a part of its vertices,
  each where the whole tree has it, so the look-ups still find every vertex that
  can be on or in a sphere.
- Otherwise (a cell of the global Delaunay step, a sphere reaching further, a
  leaf list only checked 1-irregular, a piece's
  surroundings), a k-d tree on the vertices' float coordinates proposes the
  vertices within the circumradius times (1 + 1e-9) (:func:`_candidates`); the
  element's own nodes are expected there and anything else is decided exactly:
  the float slack only widens the net.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Callable, Iterable, Mapping, NamedTuple, Sequence, Union

import numpy as np
from numpy.typing import NDArray

from ..core.geometry import Frame, Rational, in_closed_box
from ..core.morton import morton_codes
from ..core.polyhedron import measure
from ..errors import InputError
from .assembly import NODE_OFFSETS, LocalTessellation, Mesh
from .device import DeviceLayout, domain_boundary
from .report_sections import LeafMeshSummary
from .tree import distinct

# Vertices found near spheres and tested exactly, at most: each test is a few microseconds of
# Python integers and its pair ~100 bytes. A 1.38 M-leaf sphere tree needs 2.5 M; a box of
# lengths 1e-12 x 1 x 3e9 at level 5 needed 40.6 M (floats there cannot separate the vertices
# near a sphere), and at level 6 it passed 19.5 GB before the kernel killed it.
_MAX_EXACT_TESTS = 1 << 24
_PAIR_CHUNK = 1 << 22

__all__ = ["CircumcenterCheck", "ConformityCheck", "DelaunayCheck", "OpenFaces", "VolumeCheck", "check_circumcenters",
           "check_conformity", "check_delaunay", "check_volume", "element_faces", "grid_weights", "match_seams",
           "in_closed_domain", "on_domain_boundary", "pair_faces"]


@dataclass(frozen=True)
class VolumeCheck:
    """What :func:`check_volume` found: the elements' volumes summed, exactly.

    Attributes
    ----------
    volume : Fraction
        The elements' volumes summed, as a fraction of the root box's volume.
    flat_elements : int
        Elements of volume <= 0.
    volume_ok : bool
        ``volume`` is the domain's (the root box's, or a device's share of it) and no element is flat.
    """

    volume: Fraction
    flat_elements: int
    volume_ok: bool

    def figures(self) -> dict[str, bool | str | int]:
        """The report's ``volume_ok``, ``volume`` (exact text) and ``flat_elements``, in its order."""
        return {"volume_ok": self.volume_ok, "volume": str(self.volume), "flat_elements": self.flat_elements}


def check_volume(mesh: Mesh) -> VolumeCheck:
    """Volumes sum to the domain's, exactly (integers and rationals), every element of positive volume.

    Examples
    --------
    >>> from cospherical.core.configuration import Box
    >>> from cospherical.mesh.octree import build_octree, parse_shape
    >>> from cospherical.mesh.assembly import assemble
    >>> check_volume(assemble(build_octree(Box.parse([1, 2, 4]), 0, [])))
    VolumeCheck(volume=Fraction(1, 1), flat_elements=0, volume_ok=True)
    """
    depth = mesh.tree.depth
    total = Fraction(0)
    flat = 0
    for _, tessellation, leaves in mesh.groups():
        per_level = np.bincount(mesh.tree.levels[leaves].astype(np.int64), minlength=depth + 1)
        weight = sum(int(count) * 8 ** (depth - level) for level, count in enumerate(per_level.tolist()))
        total += sum((e.unit_volume for e in tessellation.elements), Fraction(0)) * weight
        flat += sum(e.unit_volume <= 0 for e in tessellation.elements) * len(leaves)
    share = total / 8 ** depth
    if mesh.cells is not None:
        per_shape = np.bincount(mesh.cells.shape, minlength=len(mesh.cells.shapes)).tolist()
        share += sum((shape.grid_volume * n for shape, n in zip(mesh.cells.shapes, per_shape)), Fraction(0)) \
            / mesh.grid ** 3
        flat += sum(n for shape, n in zip(mesh.cells.shapes, per_shape) if shape.grid_volume <= 0)
    return VolumeCheck(share, int(flat), share == mesh.domain_share and flat == 0)


Faces = Union[NDArray[np.integer[Any]], tuple[NDArray[np.integer[Any]], tuple[int, ...]]]
"""Faces of alike elements for :func:`pair_faces`: rows of cycles, or ``(table, columns)``: the rows
``table[:, columns]``."""


def _faces(mesh: Mesh, examples: int, progress: Callable[[int], None] | None = None
           ) -> tuple[dict[int, list[Faces]], ConformityCheck]:
    """The faces to pair across the mesh as rows of global vertex ids, by size (as :func:`pair_faces` reads them);
    and what the faces inside the leaves gave, paired once per configuration (see :func:`check_conformity`)."""
    by_size: dict[int, list[Faces]] = {}
    pairs = bad = 0
    shown: list[list[list[float]]] = []
    for _, tessellation, leaves in mesh.groups():
        slots = mesh.slots[leaves]
        inner_pairs, inner_bad, outer = _leaf_faces(tessellation)
        pairs += inner_pairs * len(leaves)
        bad += len(inner_bad) * len(leaves)
        if progress:
            progress((2 * inner_pairs + len(inner_bad)) * len(leaves))
        for cycle in inner_bad[:max(0, examples - len(shown))]:
            shown.append((mesh.vertices[slots[0, list(cycle)]] / mesh.grid).tolist())
        for cycle in outer:  # gathered when paired, straight into their place (pair_faces)
            by_size.setdefault(len(cycle), []).append((slots, cycle))
    for _, nodes, faces, _ in mesh.blocks(np.zeros(len(mesh.tree), dtype=bool)):  # the cells alone
        for face in faces:
            by_size.setdefault(len(face), []).append((nodes, face))
    return by_size, ConformityCheck(bad, pairs, 0, shown)


# per node (0..26), the leaf's sides it lies in, as bits: 2 * axis + (0 at the low side, 1 at the high)
_SIDES = tuple(sum(1 << (2 * axis + side) for axis in range(3) for side, at in enumerate((0, 2))
                   if int(offset[axis]) == at) for offset in NODE_OFFSETS)


def _leaf_faces(tessellation: LocalTessellation) -> tuple[int, list[tuple[int, ...]], list[tuple[int, ...]]]:
    """A configuration's element faces off its leaf's boundary, paired among themselves: how many pairs,
    and the occurrences that do not pair (cycles of node ids); and its faces in the leaf's boundary,
    which pair with other leaves' faces.

    A face off the leaf's boundary has points inside the leaf, where no other leaf's element
    reaches, so it pairs inside the leaf or nowhere: the same in every leaf of the configuration
    (slots are distinct vertices), decided here once.
    """
    met: dict[tuple[int, ...], list[bool]] = {}
    outer: list[tuple[int, ...]] = []
    for element in tessellation.elements:
        for cycle in element.faces:
            sides = _SIDES[cycle[0]]
            for node in cycle[1:]:
                sides &= _SIDES[node]
            if sides:  # every node in one of the leaf's sides
                outer.append(cycle)
                continue
            start = cycle.index(min(cycle))
            turned = cycle[start:] + cycle[:start]
            flipped = turned[1] > turned[-1]
            met.setdefault(turned[:1] + turned[:0:-1] if flipped else turned, []).append(flipped)
    pairs = 0
    unpaired: list[tuple[int, ...]] = []
    for face, orientations in met.items():
        if len(orientations) == 2 and orientations[0] != orientations[1]:
            pairs += 1
        else:
            unpaired.extend([face] * len(orientations))
    return pairs, unpaired, outer


def element_faces(vertices: NDArray[np.integer[Any]], nodes: NDArray[np.integer[Any]], sizes: NDArray[np.integer[Any]],
                  shape: NDArray[np.integer[Any]], squared: Sequence[Rational],
                  most_bytes: int | None = None,
                  owners: dict[int, list[NDArray[np.integer[Any]]]] | None = None
                  ) -> dict[int, list[NDArray[np.integer[Any]]]]:
    """Every face of elements given by their vertices, as :func:`pair_faces` reads them: by size, rows of
    vertex ids counter-clockwise seen from outside.

    ``nodes`` (elements x width, -1 padded) and ``sizes`` list each element's vertex ids
    into ``vertices`` (grid points); ``shape`` numbers the elements so that two with the
    same number are translates of each other, node for node.  A shape's faces are the hull
    of one of its elements (:func:`~cospherical.core.polyhedron.measure`, exact, in the frame
    of the box's squared lengths ``squared``), taken for all its elements at once.  A flat
    element raises :class:`~cospherical.errors.InputError`, and so do faces whose arrays (with
    what :func:`pair_faces` makes of them) would take more than ``most_bytes``, before they
    are made.  ``owners``, a dict, gets the same lists of each face's element.
    """
    order = np.argsort(shape, kind="stable")
    _, starts = np.unique(shape[order], return_index=True)
    groups = []
    for start, end in zip(starts.tolist(), np.r_[starts[1:], len(order)].tolist()):
        members = order[start:end]
        first = int(members[0])
        ids = nodes[first, :int(sizes[first])].astype(np.int64)
        corners = vertices[ids] - vertices[ids].min(axis=0)
        frame = Frame.build({i: tuple(Fraction(int(x)) for x in point) for i, point in enumerate(corners)}, squared)
        cycles = measure(frame, range(len(ids))).cycles
        if not cycles:
            raise InputError(f"element {first} is flat: it has no volume")
        groups.append((members, cycles))
    # each face's ids, their concatenation and the turned copy, and the sort's keys and order (int64)
    needed = sum(len(members) * sum(len(c) * 3 * nodes.itemsize + 16 for c in cycles) for members, cycles in groups)
    if most_bytes is not None and needed > most_bytes:
        raise InputError(f"the elements' faces need {needed:,} bytes to be paired, more than {most_bytes:,}")
    faces: dict[int, list[np.ndarray]] = {}
    for members, cycles in groups:
        rows = nodes[members]
        for cycle in cycles:
            faces.setdefault(len(cycle), []).append(rows[:, cycle])
            if owners is not None:
                owners.setdefault(len(cycle), []).append(members)
    return faces


class OpenFaces(NamedTuple):
    """Faces of one size that a piece of a partitioned mesh meets once, off the domain's boundary.

    ``faces``: rows of vertex ids, each turned to start at its smallest id and read in the
    direction whose second id is the smaller (:func:`pair_faces`); ``flipped``: per face,
    whether that reverses its orientation (counter-clockwise seen from outside its element).
    """

    size: int
    faces: NDArray[np.integer[Any]]
    flipped: NDArray[np.bool_]


@dataclass(frozen=True)
class ConformityCheck:
    """What :func:`check_conformity` (or :func:`match_seams`) found on a mesh's faces.

    Attributes
    ----------
    nonconforming_faces : int
        Face occurrences that are neither paired nor on the domain's boundary (a hanging face,
        a T-junction, an overlap).
    interior_faces : int
        Faces met twice, in opposite orientations (pairs).
    boundary_faces : int
        Faces met once, in the domain's boundary (0 for :func:`match_seams`: the pieces count them).
    nonconforming_examples : list
        Up to ``examples`` nonconforming faces, each its vertices' coordinates as fractions of
        the domain's sides (floats).
    open_faces : tuple of OpenFaces
        With ``open_faces=True`` (``mesh`` is one piece of a partitioned mesh): the faces met once
        off the domain's boundary, not counted as nonconforming but kept here, one
        :class:`OpenFaces` per face size, for :func:`match_seams` to pair with the other pieces'.
    """

    nonconforming_faces: int
    interior_faces: int
    boundary_faces: int
    nonconforming_examples: list[list[list[float]]]
    open_faces: tuple[OpenFaces, ...] = ()

    def figures(self) -> dict[str, int | list[list[list[float]]]]:
        """The report's ``nonconforming_faces``, ``interior_faces``, ``boundary_faces`` and
        ``nonconforming_examples``, in its order."""
        return {"nonconforming_faces": self.nonconforming_faces, "interior_faces": self.interior_faces,
                "boundary_faces": self.boundary_faces, "nonconforming_examples": self.nonconforming_examples}


def check_conformity(mesh: Mesh, examples: int = 5, open_faces: bool = False,
                     progress: Callable[[int], None] | None = None) -> ConformityCheck:
    """Every interior face shared by exactly two elements, same vertices, opposite orientation; the rest on the boundary.

    A face is its set of global vertex ids (the faces are convex polygons, hulls: the
    same vertices make the same polygon); its orientation is the direction its cycle
    goes on from its smallest id, to the smaller or the larger of that id's neighbours.  A face met once must lie in one plane of the domain's
    boundary; a face met twice must be met once in each orientation; anything else
    (a hanging face, a T-junction, an overlap) counts as nonconforming.  The faces off
    every leaf's boundary pair inside their leaf or not at all, alike in every leaf of a
    configuration: they are paired once per configuration; the faces in leaves' sides and
    the cells' faces are paired across the whole mesh.

    ``open_faces=True`` makes ``mesh`` one piece of a partitioned mesh: its faces met
    once off the domain's boundary are not counted but returned
    (:attr:`ConformityCheck.open_faces`), for :func:`match_seams` to pair with the other
    pieces'.  Up to ``examples`` nonconforming faces are given as vertex coordinates.
    ``progress(n)`` is told as faces are paired (``n`` more).

    Examples
    --------
    >>> from cospherical.core.configuration import Box
    >>> from cospherical.mesh.octree import build_octree, parse_shape
    >>> from cospherical.mesh.assembly import assemble
    >>> found = check_conformity(assemble(build_octree(Box.parse([1, 1, 1]), 1, [parse_shape("point:0.5,0.5,0.5")])))
    >>> found.nonconforming_faces, found.interior_faces, found.boundary_faces
    (0, 12, 24)
    """
    layout = mesh.regions.layout if mesh.regions is not None else None
    faces, inside = _faces(mesh, examples, progress)
    found = pair_faces(faces, mesh.vertices, mesh.grid, examples, open_faces, layout, progress)
    return ConformityCheck(inside.nonconforming_faces + found.nonconforming_faces,
                           inside.interior_faces + found.interior_faces, found.boundary_faces,
                           (inside.nonconforming_examples + found.nonconforming_examples)[:examples], found.open_faces)


def pair_faces(faces: Mapping[int, Sequence[Faces]], vertices: NDArray[np.integer[Any]], grid: int,
               examples: int = 5, open_faces: bool = False, layout: DeviceLayout | None = None,
               progress: Callable[[int], None] | None = None) -> ConformityCheck:
    """:func:`check_conformity` on any elements' faces: ``faces``, by size, lists of arrays whose rows are
    faces as cycles of vertex ids counter-clockwise seen from outside their element (or ``(table,
    columns)``: the rows ``table[:, columns]``, gathered here); ``vertices`` the grid points, ``grid``
    intervals per side of the box, the domain (or its union of boxes, ``layout``: see
    :func:`on_domain_boundary`).  The lists are emptied as they are read.
    """
    bad_total, interior, boundary = 0, 0, 0
    shown: list[list[list[float]]] = []
    seams: list[OpenFaces] = []
    for size, parts in sorted(faces.items()):
        # the faces are convex polygons (hulls): the same vertices are the same polygon, so a face is paired by
        # its ids in increasing order; its orientation: whether the cycle goes on from its smallest id to the
        # larger of that id's neighbours
        ends = np.cumsum([len(part[0] if isinstance(part, tuple) else part) for part in parts])
        ids = np.empty((int(ends[-1]) if len(ends) else 0, size),
                       dtype=np.result_type(*(part[0] if isinstance(part, tuple) else part for part in parts))
                       if parts else np.int64)
        flipped = np.empty(len(ids), dtype=bool)
        # per part, the columns of its rows of ids that are its cycles, or the cycles themselves
        cycles = [_ranked(part, ids[start:end], flipped[start:end])
                  for part, start, end in zip(parts, [0, *ends[:-1].tolist()], ends.tolist())]
        if isinstance(parts, list):
            parts.clear()

        order, flipped, ok, pairs, single = _paired(ids, flipped)
        interior += pairs
        on_boundary = on_domain_boundary(vertices[ids[order[single]]], grid, layout)
        ok[single[on_boundary]] = True
        boundary += int(on_boundary.sum())
        if open_faces:
            seam = single[~on_boundary]
            seams.append(OpenFaces(size, _cycles_at(order[seam], ids, cycles, ends), flipped[seam]))
            ok[seam] = True
        bad = np.flatnonzero(~ok)
        bad_total += len(bad)
        for row in _cycles_at(order[bad[:max(0, examples - len(shown))]], ids, cycles, ends):
            shown.append((vertices[row] / grid).tolist())
        if progress:
            progress(len(order))
    return ConformityCheck(int(bad_total), int(interior), int(boundary), shown, tuple(seams))


def _cycles_at(rows: NDArray[np.intp], ids: NDArray[np.integer[Any]],
               cycles: list[tuple[int, ...] | NDArray[np.integer[Any]]], ends: NDArray[np.int64]
               ) -> NDArray[np.integer[Any]]:
    """The faces at ``rows`` of ``ids`` as cycles, turned (:func:`_turned`): ``cycles[p]`` (what :func:`_ranked`
    returned of part ``p``, which ends at row ``ends[p]``) gives them back."""
    part = np.searchsorted(ends, rows, side="right")
    out = np.empty((len(rows), ids.shape[1]), dtype=ids.dtype)
    for p in distinct(part).tolist():  # sorted firsts: np.unique imports numpy.ma (16 ms) for its mask test
        here = part == p
        cycle = cycles[p]
        out[here] = _turned(ids[rows[here]][:, list(cycle)] if isinstance(cycle, tuple)
                            else cycle[rows[here] - (int(ends[p]) - len(cycle))])
    return out


def _ranked(part: Faces, ids: NDArray[np.integer[Any]], flipped: NDArray[np.bool_]
            ) -> tuple[int, ...] | NDArray[np.integer[Any]]:
    """Faces given as cycles of vertex ids (:data:`Faces`): their ids in increasing order into ``ids``, and their orientations
    (whether each cycle goes on from its smallest id to the larger of that id's two neighbours) into
    ``flipped``; returns the columns of ``ids`` that give the cycles back, else the cycles themselves.

    The faces of one element of a configuration over its leaves (or of one cell shape over
    its translates) rank their vertices alike in every row: ids are ranks of grid keys, and a
    key's order is that of its point's coordinates, which translation and scaling keep.  So the
    first row's column order sorts every row, and its orientation is every row's: one gather and
    one comparison of the result instead of a sort of each row.  Rows that do not rank alike
    (any other caller's faces) are sorted row by row.
    """
    table, cycle = part if isinstance(part, tuple) else (part, tuple(range(part.shape[1])))
    size = len(cycle)
    if not len(table):
        return table[:, list(cycle)]
    first = table[0, list(cycle)]
    columns = np.argsort(first, kind="stable")
    np.take(table, np.asarray(cycle)[columns], axis=1, out=ids)
    if bool((ids[:, 1:] > ids[:, :-1]).all()):
        at = int(columns[0])
        flipped[:] = bool(first[(at + 1) % size] > first[at - 1])
        return tuple(np.argsort(columns).tolist())
    cycles = table[:, list(cycle)] if isinstance(part, tuple) else table
    # row by row, column by column (numpy's reductions along rows of three or four are slow)
    smallest = cycles[:, 0].copy()
    for column in range(1, size):
        np.minimum(smallest, cycles[:, column], out=smallest)
    after = np.empty(len(cycles), dtype=cycles.dtype)
    before = np.empty(len(cycles), dtype=cycles.dtype)
    for column in range(size):
        here = cycles[:, column] == smallest
        after[here] = cycles[here, (column + 1) % size]
        before[here] = cycles[here, column - 1]
    np.greater(after, before, out=flipped)
    ids[:] = np.sort(cycles, axis=1)
    return cycles


def on_domain_boundary(points: np.ndarray, grid: int, layout: DeviceLayout | None = None) -> np.ndarray:
    """Per face (``points``: faces x corners x 3 grid points), whether it lies in the domain's boundary.

    The one place that says where the domain's boundary is, for the mesh's conformity check and
    for check's proof that a dual's elements are a mesh.  The domain is the box of ``grid``
    intervals per side, where a face lies in the boundary when all its corners share a
    coordinate 0 or ``grid``; or a device's union of boxes (``layout``, non-convex, with holes:
    :func:`~cospherical.mesh.device.domain_boundary`).
    """
    if layout is not None:
        return domain_boundary(layout, points, grid)
    on_boundary = np.zeros(len(points), dtype=bool)
    for axis in range(3):
        for side in (0, grid):
            on_boundary |= np.all(points[:, :, axis] == side, axis=1)
    return on_boundary


def _turned(rows: NDArray[np.integer[Any]]) -> NDArray[np.integer[Any]]:
    """Faces (cycles of ids) turned to start at their smallest id and go on to the smaller of its neighbours."""
    start = np.argmin(rows, axis=1) if len(rows) else np.zeros(0, dtype=np.intp)
    size = rows.shape[1]
    turned: NDArray[np.integer[Any]] = rows[np.arange(len(rows))[:, None], (start[:, None] + np.arange(size)) % size]
    flipped = turned[:, 1] > turned[:, -1]
    turned[flipped, 1:] = turned[flipped, :0:-1]
    return turned


def _paired(faces: NDArray[np.integer[Any]], flipped: NDArray[np.bool_]) -> tuple[
        NDArray[np.intp], NDArray[np.bool_], NDArray[np.bool_], int, NDArray[np.intp]]:
    """Sort faces (each in one canonical form: turned, or its ids sorted); mark those met exactly twice in
    opposite orientations.

    Returns the order that sorts them, their orientations in that order, the mask (in that order) of
    faces so paired, how many pairs, and the positions (in that order) of the faces met once.  The
    faces themselves are not copied in order: ``faces[order[i]]`` is the ``i``-th.
    """
    count = len(faces)
    order, keys = _row_order(faces, max(1, int(faces.max()).bit_length() if faces.size else 1))
    del faces  # the keys say all that is compared (a caller's temporary is freed here)
    flipped = flipped[order]
    new = np.ones(count, dtype=bool)
    new[1:] = False
    for key in keys:  # neighbours in the order differ where a packed key does
        new[1:] |= key[1:] != key[:-1]
    del keys
    starts = np.flatnonzero(new)
    counts = np.diff(np.r_[starts, count])
    ok = np.zeros(count, dtype=bool)
    pairs = starts[counts == 2]
    good_pairs = pairs[flipped[pairs] != flipped[pairs + 1]]
    ok[good_pairs] = ok[good_pairs + 1] = True
    return order, flipped, ok, len(good_pairs), starts[counts == 1]


def match_seams(seams: Iterable[OpenFaces], vertices: Callable[[NDArray[np.int64]], NDArray[np.int64]], grid: int,
                examples: int = 5) -> ConformityCheck:
    """Pair the faces that the pieces of a partitioned mesh left open (see :func:`check_conformity`'s ``open_faces``).

    Why this equals the check of the whole mesh: the pieces hold disjoint sets of
    elements, so a face's occurrences in the whole mesh are the sum of its
    occurrences in the pieces.  A face a piece meets once off the boundary is sent
    here; a conforming whole meets it exactly once more, in another piece, in the
    opposite orientation, so it pairs here.  Every occurrence that does not pair is
    nonconforming.  So the counts are the whole mesh's for every face met at most
    twice in all.  A face met more often has two elements on one side of it, which
    overlap: then either the exact volume sum exceeds the domain's, or some of the
    domain is left uncovered, and a face of an element bordering that gap is met
    only from one side, unpaired here or in its piece.  Either way a check fails, as
    in one process.  ``vertices(ids)`` gives grid points (for the examples).

    Returns the pairs across seams (``interior_faces``) and the faces that do not pair
    (``boundary_faces`` is 0: the pieces counted those).
    """
    seams = list(seams)
    interior = bad_total = 0
    shown: list[list[list[float]]] = []
    for size in sorted({seam.size for seam in seams}):
        parts = [seam for seam in seams if seam.size == size]
        turned = np.concatenate([seam.faces for seam in parts])
        order, _, ok, pairs, _ = _paired(turned, np.concatenate([seam.flipped for seam in parts]))
        interior += pairs
        bad = np.flatnonzero(~ok)
        bad_total += len(bad)
        for row in bad[:max(0, examples - len(shown))]:
            shown.append((vertices(turned[order[row]]) / grid).tolist())
    return ConformityCheck(int(bad_total), int(interior), 0, shown)


def _row_order(rows: np.ndarray, bits: int) -> tuple[np.ndarray, list[np.ndarray]]:
    """The lexicographic order of ``rows`` of ids below ``2**bits`` (stable: equal rows in their order), and the
    keys it sorts, in that order: ids packed into as few int64 keys as hold them (two rows are equal when
    their keys are).

    Sorting one or two keys costs a fraction of a lexicographic sort of every column.  The rows
    are sorted by their first key alone, stably (timsort: faces gathered alike, leaf after leaf,
    come in increasing runs); only the groups of equal first keys that hold rows differing in
    another key (quadrilaterals sharing their three smallest ids, rare) are then sorted by the others.
    """
    per_key = max(1, 63 // bits)
    keys = []
    for first in range(0, rows.shape[1], per_key):
        key = rows[:, first].astype(np.int64)
        for column in range(first + 1, min(first + per_key, rows.shape[1])):
            key <<= bits
            key |= rows[:, column]
        keys.append(key)
    order = np.argsort(keys[0], kind="stable")
    ranked = []
    while keys:  # each key in the order, the unordered one let go at once
        ranked.append(keys.pop(0)[order])
    if len(ranked) > 1 and len(order) > 1:
        same = ranked[0][1:] == ranked[0][:-1]  # neighbours in the order that share the first key
        differ = np.zeros(len(order) - 1, dtype=bool)
        for key in ranked[1:]:
            differ |= key[1:] != key[:-1]
        differ &= same
        if differ.any():
            group = np.cumsum(np.r_[True, ~same]) - 1
            mixed = np.zeros(int(group[-1]) + 1, dtype=bool)
            mixed[group[1:][differ]] = True
            members = np.flatnonzero(mixed[group])
            within = np.lexsort([key[members] for key in ranked[:0:-1]] + [group[members]])
            order[members] = order[members][within]
            for key in ranked:
                key[members] = key[members][within]
    return order, ranked


@dataclass(frozen=True)
class CircumcenterCheck:
    """What :func:`check_circumcenters` found: where the elements' circumcenters lie, decided exactly.

    Attributes
    ----------
    circumcenters_outside_leaf : int
        Elements whose circumcenter lies outside their own closed leaf (a cell of the global
        Delaunay subdivision counts against its first leaf).
    leaves_not_fvm_adequate : int
        Leaves with at least one such leaf element.
    elements_not_cospherical : int
        Elements whose nodes are not on one sphere: not Delaunay elements at all.
    boundary_circumcenters_outside : int
        Elements whose circumcenter lies outside the closed domain.
    """

    circumcenters_outside_leaf: int
    leaves_not_fvm_adequate: int
    elements_not_cospherical: int
    boundary_circumcenters_outside: int

    def figures(self) -> dict[str, int]:
        """The counts as the report names them, in its order."""
        return {"circumcenters_outside_leaf": self.circumcenters_outside_leaf,
                "leaves_not_fvm_adequate": self.leaves_not_fvm_adequate,
                "elements_not_cospherical": self.elements_not_cospherical,
                "boundary_circumcenters_outside": self.boundary_circumcenters_outside}


def check_circumcenters(mesh: Mesh) -> CircumcenterCheck:
    """Circumcenters in their own closed leaf, decided exactly per configuration, counted over the leaves.

    Returns a :class:`CircumcenterCheck`: elements whose circumcenter lies outside their
    leaf, leaves not FVM-adequate, elements not co-spherical, and elements whose
    circumcenter lies outside the closed domain.  Only elements at the boundary can have one (an empty sphere
    whose centre is beyond a boundary plane cuts it); there the box method's
    control volumes need the circumcenter inside, as the paper says.
    """
    outside = leaves_bad = not_spherical = 0
    for _, tessellation, leaves in mesh.groups():
        outside += sum(not e.center_in_leaf for e in tessellation.elements) * len(leaves)
        not_spherical += sum(e.sphere is None for e in tessellation.elements) * len(leaves)
        if not tessellation.fvm_adequate:
            leaves_bad += len(leaves)
    if mesh.cells is not None:
        outside += int((~mesh.cell_center_in_leaf()).sum())
    return CircumcenterCheck(int(outside), int(leaves_bad), int(not_spherical), _outside_domain(mesh))


def _outside_domain(mesh: Mesh) -> int:
    """Elements whose circumcenter lies outside the closed domain (a device's: its union of boxes), decided
    exactly in grid units."""
    grid = mesh.grid
    layout = mesh.regions.layout if mesh.regions is not None else None
    size = mesh.leaf_size()
    outside = 0
    for _, tessellation, leaves in mesh.groups():
        low = mesh.tree.positions[leaves].astype(np.int64) * size[leaves, None]
        for element in tessellation.elements:
            if element.center is None or element.center_in_leaf:
                continue  # a centre in its own closed leaf is in the closed domain: the leaf is
            # the centre in grid units is low + c * size, for c = p / q: compare q * low + p * size with 0 and q * grid,
            # in int64 when every term is below 2**62 (low and size are at most grid), else in Python integers
            numerators = [c.numerator for c in element.center]
            denominators = [c.denominator for c in element.center]
            kind = np.int64 if grid * (max(denominators) + max(map(abs, numerators))) < 2**62 else object
            p, q = np.array(numerators, dtype=kind), np.array(denominators, dtype=kind)
            at = low.astype(kind) * q[None] + p[None] * size[leaves, None].astype(kind)
            outside += int((~in_closed_domain(at, q[None], grid, layout)).sum())
    if mesh.cells is not None:
        num, den = mesh.cell_centers()
        outside += int((~in_closed_domain(num, den[:, None], grid, layout)).sum())
    return outside


def in_closed_domain(numerators: np.ndarray, denominators: np.ndarray, grid: int,
                     layout: DeviceLayout | None = None) -> np.ndarray:
    """Per rational point (``numerators`` (n x 3) over positive ``denominators``, broadcast per row or per
    axis; grid units), whether it lies in the closed domain: the box of ``grid`` intervals per side, or a
    device's union of boxes (``layout``: in the closed block of a region, decided in integers; a point on
    a block plane lies in either block beside it)."""
    inside = in_closed_box(numerators, denominators, 0, grid)
    if layout is None or not len(numerators):
        return inside
    den = np.broadcast_to(denominators, numerators.shape)
    factor = grid // layout.steps  # grid steps per step of the resolving level
    ranges = []
    for axis in range(3):
        planes = (layout.planes[axis] * factor).astype(numerators.dtype)
        scaled = planes[None, :] * den[:, axis, None]
        point = numerators[:, axis, None]
        blocks = len(planes) - 2
        low = np.clip((scaled < point).sum(axis=1) - 1, 0, blocks)  # the blocks whose closed span holds it
        high = np.clip((scaled <= point).sum(axis=1) - 1, 0, blocks)
        ranges.append((low.astype(np.int64), high.astype(np.int64)))
    held = np.zeros(len(numerators), dtype=bool)
    for i in ranges[0]:
        for j in ranges[1]:
            for k in ranges[2]:
                held |= layout.owner[i, j, k] >= 0
    return inside & held


@dataclass(frozen=True, eq=False)
class DelaunayCheck:
    """What :func:`check_delaunay` found on a mesh: the report's counts and the elements behind them.

    Attributes
    ----------
    violations : int
        Elements whose circumsphere strictly holds a mesh vertex (the report's ``delaunay_violations``).
    violating_pairs : int
        (element, vertex) pairs with the vertex strictly inside the element's sphere.
    violating_leaves : int
        Leaves holding a violating element (or giving up their place to a violating cell).
    ties : int
        (element, vertex) pairs with a vertex of another element on the sphere: the two could merge.
    exact_tests : int
        (element, vertex) pairs decided with integers.
    violating_leaf_ids : numpy.ndarray
        The violating leaves' indices, sorted.
    violating_elements : numpy.ndarray
        The violating elements' indices, sorted (the report's ``delaunay_ok`` cell data).
    not_cells : numpy.ndarray
        The elements that violate, tie or have no sphere, sorted: those that are not cells of the
        Delaunay subdivision of the vertices, which :func:`~cospherical.mesh.delaunay.global_delaunay`
        replaces.
    bounded, searched : int
        Spheres whose candidate vertices came from the tree's structure (see the module
        docstring), and spheres whose came from a k-d tree's search.
    """

    violations: int
    violating_pairs: int
    violating_leaves: int
    ties: int
    exact_tests: int
    violating_leaf_ids: NDArray[np.int64]
    violating_elements: NDArray[np.int64]
    not_cells: NDArray[np.int64]
    bounded: int = 0
    searched: int = 0

    def figures(self) -> dict[str, int]:
        """The counts as the report names them (``delaunay_violations``, ...), in its order."""
        return {"delaunay_violations": self.violations, "delaunay_violating_pairs": self.violating_pairs,
                "delaunay_violating_leaves": self.violating_leaves, "delaunay_ties": self.ties,
                "delaunay_exact_tests": self.exact_tests}

    def leaf_mesh(self, elements: int) -> LeafMeshSummary:
        """The report's ``leaf_mesh`` figures of a leaf mesh of ``elements`` elements that this check found."""
        return LeafMeshSummary(elements, self.violations, self.ties, int(len(self.not_cells)))


def check_delaunay(mesh: Mesh, workers: int = 2, progress: Callable[[int], None] | None = None) -> DelaunayCheck:
    """No mesh vertex strictly inside any element's circumsphere, decided exactly.

    Returns a :class:`DelaunayCheck`: the counts of violations and ties and the elements
    that are not cells of the Delaunay subdivision of the vertices.  Four steps: every
    element's sphere (:func:`_spheres`), the vertices that can lie on or in each (by the
    tree's structure, :func:`_local_candidates`, else those floats find near it,
    :func:`_candidates`, a k-d tree), each of those decided exactly (:func:`_exact_sides`),
    and what the signs say (:func:`_found`).

    In a mesh with re-tessellated cells (:func:`~cospherical.mesh.delaunay.global_delaunay`)
    the leaf elements and the cells marked ``proven`` passed this check on the same
    vertex set when they were kept, so only the other cells are tested (and counted in
    ``delaunay_exact_tests``); ``progress`` is told of the others at once.
    """
    spheres, local = _spheres(mesh)
    local_row, local_vertex = _local_candidates(mesh, local)
    if progress:
        progress(len(mesh) - len(spheres.searched))
    if not len(spheres.tessellation):
        none = np.zeros(0, dtype=np.int64)
        return DelaunayCheck(0, 0, 0, 0, 0, none, none, spheres.without_sphere)
    pair_row, pair_vertex = local_row, local_vertex
    if len(spheres.searched):
        found_row, found_vertex = _candidates(mesh, mesh.points(), spheres, workers, progress)
        pair_row, pair_vertex = np.r_[pair_row, found_row], np.r_[pair_vertex, found_vertex]
    return _found(mesh, spheres, pair_row, _exact_sides(mesh, spheres, pair_row, pair_vertex),
                  (len(spheres.tessellation) - len(spheres.searched), len(spheres.searched)))


class _Spheres(NamedTuple):
    """The spheres :func:`check_delaunay` tests, one row each: a leaf element's or a fresh cell's.

    ``tessellation``: the leaf's tessellation (-1: a cell); ``local``: the element in it (a
    cell: its shape); ``leaf``: the leaf (a cell: its index among the cells); ``nodes``: the
    element's vertex count; ``searched``: the rows whose vertices a k-d tree finds, and for
    them ``centers`` and ``radii`` in real units (floats: they only propose);
    ``without_sphere``: the leaf elements that have none (not co-spherical), sorted.
    """

    tessellation: np.ndarray
    local: np.ndarray
    leaf: np.ndarray
    nodes: np.ndarray
    searched: np.ndarray
    centers: np.ndarray
    radii: np.ndarray
    without_sphere: np.ndarray


class _Suspects(NamedTuple):
    """What can lie on or in a leaf element's closed sphere besides its nodes (see the module docstring).

    ``slots``: the leaf's other slots in it; ``lattice``: (m, 3) int64, the points of the
    lattice of spacing a quarter leaf, at L-infinity distance half a leaf from it, in it
    (in quarters of the leaf, from its low corner).
    """

    slots: tuple[int, ...]
    lattice: np.ndarray


# The lattice of quarter leaves around a leaf (in quarters, the leaf is 0..4 on each axis), at half a
# leaf from it (L-infinity): where vertices beside a leaf's own slots can lie within 3/4 of a leaf
_QUARTERS = np.array(list(itertools.product(range(-3, 8), repeat=3)), dtype=np.int64)
_HALF_A_LEAF_OUT = _QUARTERS[np.maximum(np.maximum(-_QUARTERS, _QUARTERS - 4), 0).max(axis=1) == 2]


def _leaf_suspects(tessellation: LocalTessellation, squared: tuple[Fraction, Fraction, Fraction]
                   ) -> list[_Suspects | None]:
    """Per element of a configuration, its :class:`_Suspects`, or ``None`` when its closed sphere reaches 3/4 of
    a leaf beyond the leaf on some axis (or it has none): decided exactly in the leaf's unit frame, where the
    squared distance is the sum over the axes of ``squared[k]`` (the box's squared lengths) times the squared
    difference.
    """
    nodes = tessellation.configuration.nodes()
    scale_w = math.lcm(*(w.denominator for w in squared))
    weights = [int(w * scale_w) for w in squared]
    # integer coordinates: unit coordinates times m (a multiple of 4, so the lattice's quarters are whole)
    m = math.lcm(4, *(c.denominator for e in tessellation.elements if e.center is not None for c in e.center),
                 *(x.denominator for point in nodes.values() for x in point))

    def scaled(point: Sequence[int | Fraction]) -> list[int]:
        return [x.numerator * (m // x.denominator) for x in point]

    whole = {s: scaled(point) for s, point in nodes.items()}
    measured = [e for e in tessellation.elements if e.center is not None]
    if not measured:
        return [None] * len(tessellation.elements)
    centers = [scaled(e.center) for e in measured if e.center is not None]
    # int64 when every term is below 2**61 (the lattice reaches 7/4 of the leaf), else Python integers
    reach = max(abs(x) for center in centers for x in center)
    kind = np.int64 if max(weights) * (2 * m + reach) ** 2 < 2**61 else object
    center_array = np.array(centers, dtype=kind)  # elements x 3
    weight_array = np.array(weights, dtype=kind)

    def squared_distances(points: np.ndarray) -> np.ndarray:
        """elements x points: the squared distances of ``points`` (n x 3, scaled) from each element's centre."""
        offsets = points[None, :, :] - center_array[:, None, :]
        distances: np.ndarray = (offsets * offsets * weight_array).sum(axis=2)
        return distances

    slot_ids = list(whole)
    to_slots = squared_distances(np.array([whole[n] for n in slot_ids], dtype=kind))
    to_lattice = squared_distances(_HALF_A_LEAF_OUT.astype(kind) * (m // 4))
    place = {n: i for i, n in enumerate(slot_ids)}
    found: list[_Suspects | None] = []
    row = 0
    for element in tessellation.elements:
        if element.center is None:
            found.append(None)
            continue
        center = centers[row]
        radius2 = int(to_slots[row, place[element.nodes[0]]])
        # the sphere's extent on each axis, from its centre: strictly inside -3/4 .. 7/4 of the leaf
        inside = all(low > 0 and high > 0 and radius2 < w * low * low and radius2 < w * high * high
                     for w, c in zip(weights, center) for low, high in [(c + 3 * m // 4, 7 * m // 4 - c)])
        if inside:
            own = set(element.nodes)
            near = to_slots[row] <= radius2
            found.append(_Suspects(tuple(n for n, i in place.items() if near[i] and n not in own),
                                   _HALF_A_LEAF_OUT[np.flatnonzero(to_lattice[row] <= radius2)]))
        else:
            found.append(None)
        row += 1
    return found


def _spheres(mesh: Mesh) -> tuple[_Spheres, list[tuple[int, np.ndarray, _Suspects]]]:
    """Every sphere to test: each leaf element's (a mesh without cells), else each fresh cell's; and, for the
    rows whose candidates the tree's structure gives, (first row, leaves, suspects) per block of alike rows.

    The leaf elements kept beside re-tessellated cells, and the cells marked proven, passed
    this very check on the same vertex set when they were chosen: only the other cells are
    tested again.
    """
    grid = mesh.grid
    scale = np.array(mesh.box.to_float()) / grid
    size = grid >> mesh.tree.levels.astype(np.int64)
    origin = mesh.tree.positions.astype(np.int64) * size[:, None]
    points = None
    rows_tessellation, rows_local, rows_leaf, n_nodes, searched, centers, radii = [], [], [], [], [], [], []
    local: list[tuple[int, np.ndarray, _Suspects]] = []
    rows = 0
    # A table element that is not co-spherical (a table may hold one) has no sphere to test, and
    # is not a cell of the Delaunay subdivision: it joins the elements that are not cells.
    without_sphere = [np.zeros(0, dtype=np.int64)]
    cells = mesh.cells
    structured = mesh.tree.vertex_balanced
    for p, tessellation, leaves in (mesh.groups() if cells is None else ()):
        suspects = _leaf_suspects(tessellation, mesh.box.squared) if structured else [None] * len(tessellation.elements)
        for j, element in enumerate(tessellation.elements):
            if element.sphere is None or element.center is None:  # check_circumcenters: not co-spherical
                without_sphere.append(mesh.element_offsets[leaves].astype(np.int64) + j)
                continue
            rows_tessellation.append(np.full(len(leaves), p, dtype=np.int32))
            rows_local.append(np.full(len(leaves), j, dtype=np.int16))
            rows_leaf.append(leaves.astype(np.int64))
            n_nodes.append(np.full(len(leaves), len(element.nodes), dtype=np.int64))
            suspect = suspects[j]
            if suspect is not None:
                local.append((rows, leaves, suspect))
            else:
                points = mesh.points() if points is None else points
                center = (origin[leaves] + np.array([float(x) for x in element.center])[None]
                          * size[leaves, None]) * scale
                first = points[mesh.slots[leaves, element.nodes[0]]]
                searched.append(np.arange(rows, rows + len(leaves)))
                centers.append(center)
                radii.append(np.sqrt(((first - center) ** 2).sum(axis=1)))
            rows += len(leaves)
    if cells is not None and len(cells):
        points = mesh.points()
        # a cell is a row of tessellation -1 whose "leaf" is its index among the cells
        fresh = np.flatnonzero(~cells.proven)
        fresh = fresh[np.argsort(cells.shape[fresh], kind="stable")]
        starts = np.searchsorted(cells.shape[fresh], np.arange(len(cells.shapes) + 1))
        for s, shape in enumerate(cells.shapes):
            chosen = fresh[starts[s]:starts[s + 1]]
            center = (cells.anchor[chosen] + np.array([float(x) for x in shape.center])[None]) * scale
            first = points[cells.nodes[chosen, 0]]
            rows_tessellation.append(np.full(len(chosen), -1, dtype=np.int32))
            rows_local.append(np.full(len(chosen), s, dtype=np.int16))
            rows_leaf.append(chosen.astype(np.int64))
            n_nodes.append(np.full(len(chosen), len(shape.offsets), dtype=np.int64))
            searched.append(np.arange(rows, rows + len(chosen)))
            centers.append(center)
            radii.append(np.sqrt(((first - center) ** 2).sum(axis=1)))
            rows += len(chosen)

    def joined(parts: list[np.ndarray], empty: np.ndarray) -> np.ndarray:
        return np.concatenate(parts) if parts else empty

    none = np.zeros(0, dtype=np.int64)
    return _Spheres(joined(rows_tessellation, none.astype(np.int32)), joined(rows_local, none.astype(np.int16)),
                    joined(rows_leaf, none), joined(n_nodes, none), joined(searched, none),
                    joined(centers, np.zeros((0, 3))), joined(radii, np.zeros(0)),
                    np.sort(np.concatenate(without_sphere))), local


def _local_candidates(mesh: Mesh, local: list[tuple[int, np.ndarray, _Suspects]]) -> tuple[np.ndarray, np.ndarray]:
    """(sphere row, vertex) pairs to decide exactly for the spheres the tree's structure bounds: per block of
    alike rows (one element of a configuration on its leaves, from ``first`` on), the leaves' slots in the
    sphere and the lattice points in it that are vertices (a grid point's key looked up among the vertices')."""
    if not local:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    grid = mesh.grid
    n = np.int64(grid + 1)
    vertices = mesh.vertices.astype(np.int64)
    keys = (vertices[:, 0] * n + vertices[:, 1]) * n + vertices[:, 2]  # increasing: a vertex's id is its rank
    size = grid >> mesh.tree.levels.astype(np.int64)
    rows_found, vertices_found = [np.zeros(0, dtype=np.int64)], [np.zeros(0, dtype=np.int64)]
    for first, leaves, suspects in local:
        rows = first + np.arange(len(leaves), dtype=np.int64)
        for slot in suspects.slots:
            rows_found.append(rows)
            vertices_found.append(mesh.slots[leaves, slot].astype(np.int64))
        if not len(suspects.lattice):
            continue
        side = size[leaves]
        low = mesh.tree.positions[leaves].astype(np.int64) * side[:, None]
        # (leaves, points, 3): a lattice point is a grid point only where a quarter leaf is whole grid steps
        scaled = suspects.lattice[None] * side[:, None, None]
        at = low[:, None] + scaled // 4
        candidate = ((scaled % 4 == 0) & (at >= 0) & (at <= grid)).all(axis=2)
        which, point = np.nonzero(candidate)
        key = (at[which, point, 0] * n + at[which, point, 1]) * n + at[which, point, 2]
        rank = np.minimum(np.searchsorted(keys, key), len(keys) - 1)
        present = keys[rank] == key
        rows_found.append(rows[which[present]])
        vertices_found.append(rank[present])
    return np.concatenate(rows_found), np.concatenate(vertices_found)


def _candidates(mesh: Mesh, points: np.ndarray, spheres: _Spheres, workers: int,
                progress: Callable[[int], None] | None) -> tuple[np.ndarray, np.ndarray]:
    """(sphere row, vertex) pairs to decide exactly: the vertices that floats put near a sphere, the
    sphere's own nodes left out, for every searched sphere (``spheres.searched``) that does not hold
    exactly its own nodes.

    A k-d tree of the vertices counts those within each sphere's radius (a hair more); the count
    is the element's node count for a sphere with nothing else near it, and only the others
    (the suspects) have their vertices listed and go to the exact test.
    """
    from scipy.spatial import cKDTree

    centers = spheres.centers
    reach = spheres.radii * (1 + 1e-9) + 1e-12 * float(np.abs(points).max())
    # Only vertices in the box around every reach can be within one: the rest are left out of the
    # search (a piece of a partitioned mesh holds all the vertices but searches its surroundings).
    low, high = (centers - reach[:, None]).min(axis=0), (centers + reach[:, None]).max(axis=0)
    lowest, highest = points.min(axis=0), points.max(axis=0)
    near = None  # every vertex (the whole mesh's check): no mask to build
    if (low > lowest).any() or (high < highest).any():
        near = np.flatnonzero(((points >= low) & (points <= high)).all(axis=1))
        if len(near) == len(points):
            near = None
    tree = cKDTree(points if near is None else points[near])
    counts = np.empty(len(centers), dtype=np.int64)
    chunk = 1 << 18
    # the spheres in Morton order: neighbouring queries walk the same branches of the tree (a quarter less CPU)
    nearby = _morton_order(centers, lowest, highest)
    for start in range(0, len(centers), chunk):
        part = nearby[start:start + chunk]
        counts[part] = tree.query_ball_point(centers[part], reach[part], return_length=True, workers=workers)
        if progress:
            progress(len(part))
    # the element's own nodes are on its sphere; anything more (or less) is looked at exactly
    suspect = np.flatnonzero(counts != spheres.nodes[spheres.searched])
    tests = int(counts[suspect].sum())
    if tests > _MAX_EXACT_TESTS:
        raise InputError(f"the exact Delaunay check needs {tests:,} sphere tests, above the bound of "
                         f"{_MAX_EXACT_TESTS:,}: on a box this stretched, floats cannot tell which vertices "
                         "are near each sphere (a coarser tree, or --delaunay leaf --no-delaunay)")
    pairs_row, pairs_vertex = [], []
    # chunks of at most _PAIR_CHUNK vertices found (a Python list of them is 36 bytes a vertex), and
    # at least one sphere each
    ends = np.searchsorted(np.cumsum(counts[suspect]), np.arange(1, tests // _PAIR_CHUNK + 2) * _PAIR_CHUNK, "right")
    for start, end in zip(np.r_[0, ends[:-1]], ends):
        rows = suspect[start:max(end, start + 1)]
        if not len(rows):
            continue
        found = tree.query_ball_point(centers[rows], reach[rows], workers=workers)
        if any(x is None for x in found):  # a search thread that ran out of memory leaves None
            raise MemoryError
        lengths = np.fromiter((len(x) for x in found), dtype=np.int64, count=len(found))
        pairs_row.append(np.repeat(spheres.searched[rows], lengths))
        found_vertices = np.fromiter((v for x in found for v in x), dtype=np.int64, count=int(lengths.sum()))
        pairs_vertex.append(found_vertices if near is None else near[found_vertices])
    pair_row = np.concatenate(pairs_row) if pairs_row else np.zeros(0, dtype=np.int64)
    pair_vertex = np.concatenate(pairs_vertex) if pairs_vertex else np.zeros(0, dtype=np.int64)
    # drop each element's own nodes
    is_cell = spheres.tessellation[pair_row] < 0
    own = np.zeros(len(pair_row), dtype=bool)
    leafy = np.flatnonzero(~is_cell)
    leaf_of_pair = spheres.leaf[pair_row[leafy]]
    nodes = mesh.element_nodes(mesh.element_offsets[leaf_of_pair] + spheres.local[pair_row[leafy]])
    own[leafy] = (nodes == pair_vertex[leafy, None]).any(axis=1)
    celly = np.flatnonzero(is_cell)
    if len(celly):
        own[celly] = (mesh.required_cells().nodes[spheres.leaf[pair_row[celly]]] == pair_vertex[celly, None]).any(axis=1)
    return pair_row[~own], pair_vertex[~own]


def _exact_sides(mesh: Mesh, spheres: _Spheres, pair_row: np.ndarray, pair_vertex: np.ndarray) -> np.ndarray:
    """Per (sphere row, vertex) pair, where the vertex lies against the sphere, decided in integers in the
    element's own frame: -1 strictly inside, 0 on it, 1 outside (int8)."""
    cells = mesh.cells
    size = mesh.grid >> mesh.tree.levels.astype(np.int64)
    origin = mesh.tree.positions.astype(np.int64) * size[:, None]
    sides = np.zeros(len(pair_row), dtype=np.int8)
    weights = grid_weights(mesh)
    rows_tessellation, rows_local, rows_leaf = spheres.tessellation, spheres.local, spheres.leaf
    for i, (row, vertex) in enumerate(zip(pair_row.tolist(), pair_vertex.tolist())):
        if rows_tessellation[row] < 0 and cells is not None:  # a cell's sphere (a mesh with cells)
            shape = cells.shapes[rows_local[row]]
            x = [int(v) - int(o) for v, o in zip(mesh.vertices[vertex], cells.anchor[rows_leaf[row]])]
            side = shape.sphere.side_at(x, weights)
        else:
            tessellation = mesh.tessellations[rows_tessellation[row]]
            element = tessellation.elements[rows_local[row]]
            leaf = rows_leaf[row]
            m = int(size[leaf])
            x = [tessellation.scale * (int(v) - int(o)) for v, o in zip(mesh.vertices[vertex], origin[leaf])]
            side = element.sphere.side_at(x, tessellation.weights, m)
        sides[i] = (side > 0) - (side < 0)
    return sides


def _found(mesh: Mesh, spheres: _Spheres, pair_row: np.ndarray, sides: np.ndarray,
           spheres_by: tuple[int, int]) -> DelaunayCheck:
    """What the exact sides of the (sphere row, vertex) pairs say: the violations, the ties, and the
    elements that are not cells of the Delaunay subdivision (those violating or tying, and those
    without a sphere)."""
    cells = mesh.cells
    rows_tessellation, rows_local, rows_leaf = spheres.tessellation, spheres.local, spheres.leaf
    inside = sides < 0
    bad_rows = distinct(pair_row[inside])

    def elements(rows: np.ndarray) -> np.ndarray:
        cell = rows_tessellation[rows] < 0
        return np.sort(np.where(cell, mesh.leaf_elements + rows_leaf[rows],
                                mesh.element_offsets[np.where(cell, 0, rows_leaf[rows])] + rows_local[rows])
                       ).astype(np.int64)

    leaf_rows = bad_rows[rows_tessellation[bad_rows] >= 0]
    bad_leaves = distinct(np.r_[rows_leaf[leaf_rows], cells.leaf[rows_leaf[bad_rows[rows_tessellation[bad_rows] < 0]]]
                                 if cells is not None else np.zeros(0, dtype=np.int64)])
    not_cells = np.sort(np.r_[elements(distinct(pair_row[sides <= 0])), spheres.without_sphere])
    return DelaunayCheck(int(len(bad_rows)), int(inside.sum()), int(len(bad_leaves)), int((sides == 0).sum()),
                         int(len(pair_row)), bad_leaves, elements(bad_rows), not_cells, *spheres_by)


def _morton_order(points: np.ndarray, low: np.ndarray, high: np.ndarray, bits: int = 10) -> np.ndarray:
    """The order of ``points`` along the Z-order curve of a ``2**bits`` grid on the box ``low``..``high``."""
    cell = np.clip((points - low) * ((1 << bits) / np.maximum(high - low, 1e-300)), 0, (1 << bits) - 1)
    return np.argsort(morton_codes(cell.astype(np.int64)), kind="stable")


def grid_weights(mesh: Mesh) -> tuple[int, int, int]:
    """The box's squared lengths as integers in one ratio: the weights of the grid frame."""
    squared = mesh.box.squared
    den = math.lcm(*(w.denominator for w in squared))
    return int(squared[0] * den), int(squared[1] * den), int(squared[2] * den)
