"""The conformity check: every interior face shared by exactly two elements, in opposite orientations,
the rest in the domain's boundary; decided on global vertex ids.

The faces off a leaf's boundary pair inside their leaf or nowhere, alike in every leaf of a
configuration: they are paired once per configuration.  The faces in the leaves' sides (and the
cells' faces) are sorted as packed integer keys and paired across the whole mesh
(:func:`pair_faces`); a partitioned mesh's pieces leave their open faces to :func:`match_seams`.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING, Any, Callable, Iterable, Mapping, NamedTuple, Sequence, Union

import numpy as np
from numpy.typing import NDArray

from ...core.geometry import Frame, Rational
from ...core.polyhedron import measure
from ...errors import InputError
from ..assembly import NODE_OFFSETS, LocalTessellation, Mesh
from ..tree import distinct
from .domain import on_domain_boundary

if TYPE_CHECKING:  # a device's module is imported where a device is meshed
    from ..device import DeviceLayout

__all__ = ["ConformityCheck", "Faces", "OpenFaces", "check_conformity", "element_faces", "match_seams", "pair_faces"]


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
        cycles = _ranked_parts(parts, ids, flipped, [0, *ends[:-1].tolist()], ends.tolist())
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


def _ranked_parts(parts: Sequence[Faces], ids: NDArray[np.integer[Any]], flipped: NDArray[np.bool_],
                  starts: list[int], ends: list[int]) -> list[tuple[int, ...] | NDArray[np.integer[Any]]]:
    """:func:`_ranked` of every part (part ``p`` into rows ``starts[p]:ends[p]`` of ``ids`` and ``flipped``);
    the consecutive parts that are columns of one table (a configuration's faces of one size over its
    leaves, a cell shape's over its translates) ranked together: their first row's column orders,
    orientations and the check that every row ranks alike, in a few array operations for all of them
    instead of a handful each (a level-7 sphere tree has ~1,600 parts, ~100 tables).  A part whose
    rows do not rank alike is ranked alone, row by row, as :func:`_ranked` does."""
    cycles: list[tuple[int, ...] | NDArray[np.integer[Any]]] = []
    p = 0
    while p < len(parts):
        part = parts[p]
        q = p + 1
        if isinstance(part, tuple):
            while q < len(parts) and isinstance(parts[q], tuple) and parts[q][0] is part[0]:
                q += 1
        if q - p == 1 or not len(part[0]):
            cycles.extend(_ranked(parts[k], ids[starts[k]:ends[k]], flipped[starts[k]:ends[k]]) for k in range(p, q))
            p = q
            continue
        table = part[0]
        group = np.array([parts[k][1] for k in range(p, q)], dtype=np.intp)  # (parts, size): node columns
        first = table[0][group]
        columns = np.argsort(first, axis=1, kind="stable")
        ordered = np.take_along_axis(group, columns, axis=1)
        for k in range(p, q):
            np.take(table, ordered[k - p], axis=1, out=ids[starts[k]:ends[k]])
        block = ids[starts[p]:ends[q - 1]]
        increasing = block[:, 1] > block[:, 0]  # column by column: numpy's reductions along rows of 3 or 4 are slow
        for column in range(2, block.shape[1]):
            increasing &= block[:, column] > block[:, column - 1]
        alike: list[bool] = np.asarray(increasing.reshape(q - p, len(table)).all(axis=1), dtype=bool).tolist()
        at = columns[:, 0]
        turns = first[np.arange(q - p), (at + 1) % group.shape[1]] > first[np.arange(q - p), at - 1]
        flipped[starts[p]:ends[q - 1]] = np.repeat(turns, len(table))
        for k, (back, same) in enumerate(zip(np.argsort(columns, axis=1).tolist(), alike), p):
            cycles.append(tuple(back) if same else _ranked(parts[k], ids[starts[k]:ends[k]], flipped[starts[k]:ends[k]]))
        p = q
    return cycles


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
