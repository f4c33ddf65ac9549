"""The paper's criteria: which element types to keep, and how to split the rest.

For a study and a splitting criterion, the kept set is the smallest set of
element types such that every element of the study is kept or split (in one
step or several, which is the same as one finer split) into kept types.  Ties
go to the set that gives the fewest elements over all configurations, then to
the smallest list of type ids.  The search is exact: branch and bound over the
elements still not covered, always branching on the one with fewest options.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, replace
from typing import Literal, Sequence, overload

from ..caches import cached
from ..choices import SPLIT_CRITERIA
from ..core.geometry import Frame, Rational
from ..core.polyhedron import Polyhedron
from ..core.split import subdivisions
from ..core.tessellation import Element, Tessellation
from .model import Catalogue
from .names import shipped_catalogue

__all__ = ["Choice", "apply_catalogue_criterion", "choose", "choose_kept",
           "element_options", "kept_split", "minimal_kept_sets", "option_types", "split_options", "split_positions", "split_tessellation",
           "SplitPositions"]

# A split as the catalogue records it: per piece its type id and its nodes as positions in the parent's reference order.
SplitPositions = tuple[tuple[str, tuple[int, ...]], ...]


def element_options(tess: Tessellation, element: Element, criterion: str) -> tuple[tuple[Element, ...], ...]:
    """Every split of an element under a criterion (the element itself first), pieces classified."""
    poly = element.polyhedron
    if len(poly.nodes) == 4:
        # A tetrahedron has no split: its one option without split_options' cache key,
        # whose Fraction coordinates are slow to hash (half the elements of a study).
        return ((Element.from_polyhedron(poly),),)
    points = tuple((n, tess.nodes[n]) for n in poly.nodes)
    return split_options(points, tess.configuration.box.squared, poly, criterion)


# The same element (same node ids at the same places) recurs across configurations.
@cached(maxsize=1 << 14)
def split_options(points: tuple[tuple[int, Sequence[Rational]], ...], squared: Sequence[Rational], poly: Polyhedron,
                  criterion: str) -> tuple[tuple[Element, ...], ...]:
    """Every split of the polyhedron ``poly`` with ``points`` ((node, unit coordinates) pairs)
    under a criterion, the element itself first, pieces classified."""
    if criterion == "internal_faces":
        # The internal-face splits are exactly the internal-edge splits whose pieces
        # have only the element's own edges (the two criteria differ in nothing
        # else): filter the other search's result, already sorted, instead of
        # searching twice (a third of a bisection study's time).
        edges = set(poly.edges)
        return tuple(option for option in split_options(points, squared, poly, "internal_edges_and_faces")
                     if all(edge in edges for piece in option for edge in piece.polyhedron.edges))
    split_criterion = next((c for c in SPLIT_CRITERIA if c == criterion), None)
    if split_criterion is None:
        raise ValueError(f"{criterion!r} is not a split criterion")
    frame = Frame.build(dict(points), squared)
    options = []
    for split in subdivisions(frame, poly, split_criterion):
        options.append(tuple(Element.from_polyhedron(piece) for piece in split))
    # Fewest pieces, then the smallest multiset of piece types: a rule a symmetry cannot change,
    # so every member of an orbit is split alike (node lists only break the remaining ties).
    options.sort(key=lambda pieces: (len(pieces), sorted(p.type.id for p in pieces), [p.polyhedron.nodes for p in pieces]))
    return tuple(options)


def minimal_kept_sets(instances: list[set[frozenset[str]]]) -> tuple[int, list[frozenset[str]]]:
    """All smallest type sets K such that every instance has an option (a set of types) inside K.

    Each instance is the set of its options; an option is the set of the types of a
    split's pieces (the unsplit element is the option of its own type).
    """
    distinct = sorted({frozenset(options) for options in instances}, key=lambda o: sorted(map(sorted, o)))
    # One option per element, the one with fewest types, is always a solution: an upper bound.
    best = [len(frozenset().union(*[min(o, key=len) for o in distinct])) if distinct else 0]
    solutions: set[frozenset[str]] = set()
    visited: set[frozenset[str]] = set()

    def search(kept: frozenset[str]) -> None:
        if kept in visited or len(kept) > best[0]:
            return
        visited.add(kept)
        open_instances = [options for options in distinct if not any(o <= kept for o in options)]
        if not open_instances:
            if len(kept) < best[0]:
                best[0] = len(kept)
                solutions.clear()
            solutions.add(kept)
            return
        if len(kept) + 1 > best[0]:
            return
        options = min(open_instances, key=len)
        for option in sorted(options, key=lambda o: (len(o - kept), sorted(o))):
            search(kept | option)

    search(frozenset())
    return best[0], sorted(solutions, key=sorted)


@dataclass(frozen=True)
class Choice:
    """A criterion applied to a study: the kept types and the pieces of every element.

    ``splits`` counts, per element type that is not kept, the splits used, each
    weighted by the configurations it occurs in.  A split is a tuple of pieces
    ``(type id, positions)``, positions indexing the parent's reference order.
    """

    criterion: str
    kept: frozenset[str]
    tessellations: dict[str, Tessellation]  # orbit representative -> tessellation after splitting
    splits: dict[str, Counter[SplitPositions]]


@overload
def split_tessellation(tess: Tessellation, kept: frozenset[str], criterion: str,
                       strict: Literal[False]) -> tuple[Tessellation, list[tuple[Element, tuple[Element, ...]]]]: ...
@overload
def split_tessellation(tess: Tessellation, kept: frozenset[str], criterion: str,
                       strict: bool = True) -> tuple[Tessellation, list[tuple[Element, tuple[Element, ...]]]] | None: ...
def split_tessellation(tess: Tessellation, kept: frozenset[str], criterion: str,
                       strict: bool = True) -> tuple[Tessellation, list[tuple[Element, tuple[Element, ...]]]] | None:
    """Split every element whose type is not kept into kept types, fewest pieces first.

    Returns ``(tessellation, used)`` with ``used`` the list of (element, pieces)
    split; ``None`` when ``strict`` and some element has no such split (with
    ``strict=False`` it stays whole).
    """
    elements = []
    used = []
    for element in tess.elements:
        if element.type.id in kept or criterion == "optimal":
            elements.append(element)
            continue
        pieces = kept_split(element_options(tess, element, criterion), kept)
        if pieces is None:
            if strict:
                return None
            elements.append(element)
            continue
        elements.extend(pieces)
        used.append((element, pieces))
    elements.sort(key=lambda e: e.polyhedron.nodes)
    # replace, not a new Tessellation: a shape's tessellation keeps its own FVM test
    return replace(tess, elements=tuple(elements)), used


def kept_split(options: Sequence[tuple[Element, ...]], kept: frozenset[str]) -> tuple[Element, ...] | None:
    """The split an element takes under a kept set: the first of its options (fewest pieces
    first, see :func:`split_options`) whose pieces are all kept; ``None`` if there is none."""
    return next((option for option in options if all(piece.type.id in kept for piece in option)), None)


def option_types(option: Sequence[Element]) -> tuple[str, ...]:
    """The sorted type ids of a split's pieces: what a kept set must contain for the split to be usable."""
    return tuple(sorted(piece.type.id for piece in option))


def choose_kept(instances: Sequence[Sequence[tuple[str, ...]]], weights: Sequence[int]) -> tuple[frozenset[str], list[int]]:
    """The kept set of a criterion, and the option each element uses: the rule every study follows.

    Parameters
    ----------
    instances : sequence of sequences of type-id tuples
        Per element (or per distinct element), its options in the order they are
        preferred (:func:`split_options`: the element itself first, then fewest
        pieces), each as :func:`option_types`.
    weights : sequence of int
        How many elements of the study each instance stands for.

    Returns
    -------
    kept : frozenset of str
        Among the smallest type sets into which every instance splits
        (:func:`minimal_kept_sets`), the one that gives the fewest elements in
        all, then the smallest sorted list of ids.
    chosen : list of int
        Per instance, the index of its first option inside ``kept``.

    Examples
    --------
    >>> kept, chosen = choose_kept([[("a",), ("b", "c")], [("b",)], [("c",), ("a", "b")]], [1, 1, 5])
    >>> sorted(kept), chosen
    (['b', 'c'], [1, 0, 0])
    """
    _, candidates = minimal_kept_sets([{frozenset(option) for option in options} for options in instances])
    best = None
    for kept in candidates:
        chosen = [next(i for i, option in enumerate(options) if set(option) <= kept) for options in instances]
        total = sum(weight * len(options[i]) for weight, options, i in zip(weights, instances, chosen))
        if best is None or (total, sorted(kept)) < best[0]:
            best = ((total, sorted(kept)), kept, chosen)
    assert best is not None, "minimal_kept_sets gives at least one set"
    return best[1], best[2]


def choose(tessellations: dict[str, Tessellation], sizes: dict[str, int], criterion: str) -> Choice:
    """Apply a criterion to the orbit representatives of a study (``sizes``: orbit sizes)."""
    if criterion == "optimal":
        kept = frozenset(e.type.id for t in tessellations.values() for e in t.elements)
        return Choice(criterion, kept, tessellations, {})
    elements = [(rep, element_options(tess, element, criterion))
                for rep, tess in tessellations.items() for element in tess.elements]
    kept, _ = choose_kept([[option_types(o) for o in options] for _, options in elements],
                          [sizes[rep] for rep, _ in elements])
    split: dict[str, Tessellation] = {}
    splits: dict[str, Counter[SplitPositions]] = {}
    for rep, tess in tessellations.items():
        done = split_tessellation(tess, kept, criterion)
        assert done is not None, "choose_kept's set splits every element into kept types"
        split[rep], used = done
        for element, pieces in used:
            splits.setdefault(element.type.id, Counter())[split_positions(element, pieces)] += sizes[rep]
    return Choice(criterion, kept, split, splits)


def split_positions(element: Element, pieces: Sequence[Element]) -> SplitPositions:
    """A split as the catalogue records it: (piece type, piece nodes as positions in the element's
    reference order), sorted."""
    position = {node: i for i, node in enumerate(element.nodes)}
    return tuple(sorted((p.type.id, tuple(position[n] for n in p.nodes)) for p in pieces))


def apply_catalogue_criterion(tess: Tessellation, criterion: str, catalogue: Catalogue | None = None) -> Tessellation:
    """Split a tessellation's elements by the catalogue's (default: the shipped one's) kept types for a criterion.

    The catalogue keeps, per criterion, the union of its studies' kept sets. An
    element of a type it does not keep is split into kept types, fewest pieces
    first; an element with no such split (a type no study met) stays whole.
    """
    if criterion == "optimal":
        return tess
    catalogue = shipped_catalogue() if catalogue is None else catalogue
    return split_tessellation(tess, catalogue.kept(criterion), criterion, strict=False)[0]
