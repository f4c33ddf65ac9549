"""The intersection study's statistics from its two stages, in the summary shape every study shares,
and the entries (:class:`ElementEntry`) that describe its distinct elements to them.

The counting is vectorised (millions of configurations); the kept sets and the
frequency tables come from the same functions as the bisection study's
(:func:`cospherical.catalogue.choose_kept`, :func:`cospherical.studies.summary.frequency_table`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ...catalogue import choose_kept
from ...choices import SPLIT_CRITERIA
from ..summary import TypeInfo, frequency_table

__all__ = ["ElementEntry", "statistics"]


@dataclass(frozen=True)
class ElementEntry:
    """A distinct element of the study: its type id and, per split criterion, its options
    (sorted piece-type tuples, the element itself first, in the order the criteria prefer them)."""

    type: str
    options: dict[str, tuple[tuple[str, ...], ...]]

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> ElementEntry:
        return cls(data["type"], {c: tuple(map(tuple, o)) for c, o in data["options"].items()})


def statistics(sizes: np.ndarray, cells: dict[str, np.ndarray], element_of: np.ndarray, entries: list[ElementEntry],
               types: dict[str, TypeInfo]) -> dict[str, Any]:
    """FVM counts and, per criterion, the kept types, totals, frequencies and splits.

    ``entries[e]`` describes element e (entry 0 the tetrahedron); ``element_of``
    gives each non-tetrahedral cell's entry, in the order of ``cells``.
    """
    sizes = np.asarray(sizes, dtype=np.int64)
    n = len(sizes)
    # One row per (configuration, element), tetrahedra as one row with their count.
    config = np.concatenate([np.arange(n), np.repeat(np.arange(n), cells["polys"])])
    element = np.concatenate([np.zeros(n, dtype=np.int64), element_of])
    multiplicity = np.concatenate([cells["tets"], np.ones(len(element_of), dtype=np.int64)])
    keep = multiplicity > 0
    config, element, multiplicity = config[keep], element[keep], multiplicity[keep]
    weight = np.bincount(element, weights=sizes[config] * multiplicity, minlength=len(entries)).astype(np.int64)
    used = [e for e in range(len(entries)) if weight[e] > 0]

    criteria = {}
    for criterion in ("optimal", *SPLIT_CRITERIA):
        pieces: list[tuple[str, ...]] = [(entry.type,) for entry in entries]
        splits: dict[str, dict[tuple[str, ...], int]] = {}
        if criterion != "optimal":
            kept, chosen = choose_kept([entries[e].options[criterion] for e in used], [int(weight[e]) for e in used])
            for e, i in zip(used, chosen):
                pieces[e] = entries[e].options[criterion][i]
                if i:  # option 0 is the element itself
                    by_pieces = splits.setdefault(entries[e].type, {})
                    by_pieces[pieces[e]] = by_pieces.get(pieces[e], 0) + int(weight[e])
        counts, configurations = _counts(pieces, weight, sizes, config, element)
        criteria[criterion] = frequency_table(counts, configurations, types, splits)
        if criterion != "optimal":
            criteria[criterion]["kept"] = sorted(kept)
    return {
        "fvm_adequate": int(sizes[cells["closed"]].sum()),
        "fvm_adequate_open": int(sizes[cells["open"]].sum()),
        "criteria": criteria,
    }


def _counts(pieces: list[tuple[str, ...]], weight: np.ndarray, sizes: np.ndarray, config: np.ndarray,
            element: np.ndarray) -> tuple[dict[str, int], dict[str, int]]:
    """Per type: its elements, and the configurations holding at least one (weighted by orbit size)."""
    type_ids = sorted({t for e in range(len(pieces)) if weight[e] > 0 for t in pieces[e]})
    index = {t: i for i, t in enumerate(type_ids)}
    counts = np.zeros(len(type_ids), dtype=np.int64)
    for e, element_pieces in enumerate(pieces):
        if weight[e] > 0:
            for t in element_pieces:
                counts[index[t]] += weight[e]
    # Configurations holding a type: distinct (configuration, type) pairs, weighted by orbit size.
    distinct_types = [sorted({index[t] for t in p if t in index}) for p in pieces]
    per_element = np.array([len(d) for d in distinct_types], dtype=np.int64)
    flat = np.array([t for d in distinct_types for t in d], dtype=np.int64)
    offsets = np.concatenate([[0], np.cumsum(per_element)])
    repeat = per_element[element]
    rows = np.repeat(config, repeat)
    within = np.arange(len(rows)) - np.repeat(np.cumsum(repeat) - repeat, repeat)
    type_of = flat[np.repeat(offsets[element], repeat) + within]
    pairs = np.unique(rows * len(type_ids) + type_of)
    configurations = np.bincount(pairs % len(type_ids), weights=sizes[pairs // len(type_ids)],
                                 minlength=len(type_ids)).astype(np.int64)
    return ({t: int(counts[i]) for i, t in enumerate(type_ids)},
            {t: int(configurations[i]) for i, t in enumerate(type_ids)})
