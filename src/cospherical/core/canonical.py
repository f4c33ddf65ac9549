"""Canonical code of a polyhedron's labelled face graph.

The vertex-edge graph of a convex polyhedron is planar and 3-connected, so its
embedding (the cyclic order of neighbours around each vertex) is unique up to
mirror image.  From a starting dart (directed edge) and an orientation, a
breadth-first walk numbers the vertices in order of discovery and lists, for
every vertex, its neighbours' numbers in rotation order together with the kind
of the face on the dart's left.  That list determines the labelled map
completely, so the smallest list over all darts and both orientations is a
canonical form: two polyhedra share it exactly when their labelled face graphs
are isomorphic (mirror images included).  The minimising walk's discovery order
is the type's reference vertex order.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Sequence

from ..caches import cached

__all__ = ["CanonicalForm", "canonical_form", "KIND_LETTERS"]

# Order matters only for which walk is smallest; letters make the code readable.
KIND_LETTERS = {
    "triangle": "t",
    "rectangle": "r",
    "quadrilateral": "q",
    "pentagon": "p",
    "hexagon": "h",
    "heptagon": "s",
    "octagon": "o",
}
_KIND_RANK = {kind: rank for rank, kind in enumerate(KIND_LETTERS)}
_END = -1  # closes one vertex's neighbour list


@dataclass(frozen=True)
class CanonicalForm:
    """``code``: the canonical string; ``order``: vertices in reference order.

    ``mirrored`` is True when only the mirror image's walk gives the code: the
    polyhedron is then the mirror image of the type's direct form (a chiral
    type met in its other handedness), so its faces, listed in the reference
    order, run the other way round.  A mirror-symmetric type is never mirrored.
    """

    code: str
    order: tuple[int, ...]
    mirrored: bool = False


def _kind_rank(kind: str) -> int:
    if kind in _KIND_RANK:
        return _KIND_RANK[kind]
    return 100 + int(kind.split("-")[0])  # "9-gon"


def _kind_letter(rank: int) -> str:
    if rank < 100:
        return list(KIND_LETTERS.values())[rank]
    return f"g{rank - 100}"


def canonical_form(faces: Sequence[Sequence[int]], kinds: Sequence[str]) -> CanonicalForm:
    """Canonical code of the map given by face cycles (counter-clockwise from outside).

    Examples
    --------
    >>> tetra = [(0, 2, 1), (0, 1, 3), (1, 2, 3), (0, 3, 2)]
    >>> canonical_form(tetra, ["triangle"] * 4).code
    'v4:1t2t3t/0t3t2t/0t1t3t/0t2t1t'
    """
    return _canonical_form(tuple(map(tuple, faces)), tuple(kinds))


# The same cell (same node ids, same faces) recurs across the configurations of
# a study, so the pure function is memoised on its exact input.
@cached(maxsize=1 << 16)
def _canonical_form(faces: tuple[tuple[int, ...], ...], kinds: tuple[str, ...]) -> CanonicalForm:
    # For a face (..., u, v, w, ...) the next neighbour of v after w, turning
    # counter-clockwise seen from outside, is u; that face lies left of v->w.
    turn: dict[tuple[int, int], int] = {}
    left: dict[tuple[int, int], int] = {}
    for face, kind in zip(faces, kinds):
        rank = _kind_rank(kind)
        n = len(face)
        for i in range(n):
            u, v, w = face[i - 1], face[i], face[(i + 1) % n]
            turn[v, w] = u
            left[v, w] = rank
    mirror_turn = {(v, u): w for (v, w), u in turn.items()}
    mirror_left = {(v, w): left[w, v] for (v, w) in left}

    # A walk's list opens with the first vertex's neighbours 1..d and their face
    # labels, then the end mark; only darts with the smallest such opening can
    # give the smallest list, so only they are walked.
    candidates = []
    for rotation, label in ((turn, left), (mirror_turn, mirror_left)):
        for start in turn:
            v, w = start
            opening = []
            while True:
                opening.append(label[v, w])
                w = rotation[v, w]
                if w == start[1]:
                    break
            candidates.append((len(opening), opening, start, rotation, label, rotation is mirror_turn))
    smallest = min(candidates, key=lambda c: c[:2])[:2]
    best: list[int] | None = None
    best_order: list[int] = []
    best_mirrored = False
    for size, opening, start, rotation, label, mirrored in candidates:
        if (size, opening) != smallest:
            continue
        code, order = _walk(start, rotation, label)
        # direct walks come first, so a tie keeps the direct orientation
        if best is None or code < best:
            best, best_order, best_mirrored = code, order, mirrored
    assert best is not None
    return CanonicalForm(_encode(best, len(best_order)), tuple(best_order), best_mirrored)


def _walk(start: tuple[int, int], rotation: Mapping[tuple[int, int], int],
          label: Mapping[tuple[int, int], int]) -> tuple[list[int], list[int]]:
    """The walk's list from the dart ``start``, and the vertices in discovery order."""
    v0, w0 = start
    number = {v0: 0}
    order = [v0]
    entry = {v0: w0}
    code: list[int] = []
    for v in order:  # grows while we walk
        first = w = entry[v]
        while True:
            if w not in number:
                number[w] = len(order)
                order.append(w)
                entry[w] = v
            code.append(number[w])
            code.append(label[v, w])
            w = rotation[v, w]
            if w == first:
                break
        code.append(_END)
    return code, order


def _encode(code: list[int], vertices: int) -> str:
    lists: list[str] = []
    current: list[str] = []
    items = iter(code)
    for x in items:
        if x == _END:
            lists.append("".join(current))
            current = []
        else:
            current.append(f"{x}{_kind_letter(next(items))}")
    return f"v{vertices}:" + "/".join(lists)
