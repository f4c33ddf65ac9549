"""The intersection study's pattern table, computed: one entry per orbit representative, built from cells.

At 1/16 the table has 1.66 million entries; tessellating each again in Python
(1-4 ms) would take an hour.  But the entries are made of few distinct elements:
a cell is the same element, with the same pattern-table text under every
criterion, wherever its nodes sit at the same places.  So the table is built in
three passes (:class:`TableRun`):

1. **cells**: the compiled walk gives every representative's cells, each as (node
   mask, code masked to the digits its points depend on), as in the study's
   stage 1; the distinct pairs are collected (workers, in chunks).
2. **elements**: each distinct cell is classified, measured and split under every
   criterion's kept set once, by the exact Python path, and written as its
   pattern-table text (workers, in chunks): at 1/16 a few hundred thousand cells.
3. **entries**: the walk runs again on each chunk (workers, each given the texts
   of its chunk's cells) and every representative's line is joined from its
   cells' texts, exactly as :func:`~cospherical.formats.patterns.configuration_line`
   writes it from a tessellation (tested: the same bytes); the chunks come back
   in code order.

Writing the table (YAML, indexed store) is
:func:`cospherical.formats.intersection_table.write_pattern_table`'s job.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Callable, Iterator, TypeVar

import numpy as np

from ...catalogue import kept_split, split_options
from ...core.symmetry import key_code
from ...core.tessellation import Element, element_entry
from ...errors import InputError
from ...execution.backends import Backend, completed
from ...files.flowyaml import flow
from .family import orbits
from .run import cell_polyhedron, tessellate_chunk

__all__ = ["CHUNK", "CellText", "TableRun", "cell_texts", "distinct_cells", "representative_cells", "table_entries"]

CHUNK = 20_000
_T = TypeVar("_T")
_CELL_CHUNK = 2_000


def representative_cells(codes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per configuration (base-16 codes) its cell count, and per cell, in the walk's order, its
    node mask and masked code (see :func:`cospherical.core.compiled.cube_batch`)."""
    cells = tessellate_chunk(codes, every_cell=True)
    return cells["polys"], cells["poly_mask"], cells["poly_code"]


def distinct_cells(codes: np.ndarray) -> np.ndarray:
    """Pass 1 on a chunk: its distinct cells as rows (node mask, masked code, a configuration holding it)."""
    counts, masks, masked = representative_cells(codes)
    owners = np.repeat(np.asarray(codes, dtype=np.int64), counts)
    pairs = np.stack([masks, masked], axis=1)
    _, first = np.unique(pairs, axis=0, return_index=True)
    return np.stack([masks[first], masked[first], owners[first]], axis=1)


@dataclass(frozen=True)
class CellText:
    """A distinct cell's part of every entry holding it.

    ``closed``: its circumcenter lies in the closed box (the entry's ``fvm_adequate``);
    ``pieces``: per criterion, the elements it becomes there, as (nodes in id order,
    element text), the cell itself under ``optimal`` and wherever its type is kept.
    """

    closed: bool
    pieces: tuple[tuple[tuple[tuple[int, ...], str], ...], ...]


def cell_texts(cells: list[tuple[int, int, int]], kept: dict[str, list[str]]) -> list[CellText]:
    """Pass 2: every cell ``(node mask, masked code, a configuration code holding it)`` as its
    :class:`CellText`, criteria ``optimal`` then those of ``kept`` (criterion -> kept type ids)."""
    scale = (1.0, 1.0, 1.0)
    kept_sets = {criterion: frozenset(types) for criterion, types in kept.items()}
    found = []
    for mask, _, owner in cells:
        points, poly = cell_polyhedron(mask, owner)
        element = Element.from_polyhedron(poly)
        pieces: list[tuple[Element, ...]] = [(element,)]
        for criterion, types in kept_sets.items():
            if element.type.id in types:
                pieces.append((element,))
                continue
            split = kept_split(split_options(points, (1, 1, 1), poly, criterion), types)
            if split is None:
                raise InputError(f"a {element.type.name} has no {criterion} split into the kept types")
            pieces.append(split)
        found.append(CellText(
            poly.center_in_box(closed=True),
            tuple(tuple((p.polyhedron.nodes, flow(element_entry(p, scale))) for p in option) for option in pieces)))
    return found


def table_entries(codes: np.ndarray, cells: Mapping[tuple[int, int], CellText], criteria: list[str]) -> list[tuple[str, str]]:
    """The pattern-table entries of some representatives as (code, entry JSON), joined from their
    cells' texts (``cells``: (node mask, masked code) -> :class:`CellText`, every cell they hold)."""
    counts, masks, masked = representative_cells(codes)
    held = [cells[pair] for pair in zip(masks.tolist(), masked.tolist())]
    entries = []
    start = 0
    for code, count in zip(codes, counts.tolist()):
        mine = held[start:start + count]
        start += count
        parts = [f'"fvm_adequate": {"true" if all(cell.closed for cell in mine) else "false"}']
        written: dict[tuple[tuple[int, ...], ...], str] = {}
        for k, criterion in enumerate(criteria):
            # in node-id order, as a tessellation sorts its elements; the same
            # elements as an earlier criterion are that criterion's name
            pieces = sorted(piece for cell in mine for piece in cell.pieces[k])
            key = tuple(nodes for nodes, _ in pieces)
            if key in written:
                parts.append(f'"{criterion}": "{written[key]}"')
                continue
            written[key] = criterion
            parts.append(f'"{criterion}": [' + ", ".join(text for _, text in pieces) + "]")
        entries.append((key_code(int(code)), "{" + ", ".join(parts) + "}"))
    return entries


def _finished_chunk(codes: np.ndarray, cells: Mapping[tuple[int, int], CellText], criteria: list[str],
                    finish: Callable[..., _T], *args: object) -> _T:
    """Pass 3 on a chunk (in a worker): its entries as (code, entry JSON), handed to ``finish(entries, *args)``."""
    return finish(table_entries(codes, cells, criteria), *args)


class TableRun:
    """The three passes of an intersection pattern table for a study's ``summary`` (its kept sets).

    ``progress(stage, n)`` as work finishes: ``cells`` and ``entries`` in
    representatives, ``elements`` in distinct cells.  The work runs on the
    backend of :func:`~cospherical.execution.backends.completed` (``jobs``,
    ``scheduler``, ``dask_workers``).
    """

    def __init__(self, summary: dict[str, Any], jobs: int = 1, progress: Callable[[str, int], None] | None = None,
                 scheduler: str | None = None,
                 dask_workers: int | None = None, chunk: int = CHUNK) -> None:
        self.resolution, self.order = summary["resolution"], summary["insertion_order"]
        self.reps, _, _ = orbits(self.resolution, self.order)
        self.kept = {c: data["kept"] for c, data in summary["criteria"].items() if c != "optimal"}
        self.criteria = ["optimal", *self.kept]
        self.chunk = chunk
        self._report = progress or (lambda stage, n: None)
        self._backend = Backend(jobs=jobs, scheduler=scheduler, dask_workers=dask_workers)
        self._held: dict[int, list[tuple[int, int]]] | None = None
        self._texts: dict[tuple[int, int], CellText] = {}

    def cells(self) -> None:
        """Passes 1 and 2: the distinct cells of each chunk and of the whole table, each one's text once."""
        reps, chunk, backend = self.reps, self.chunk, self._backend
        held: dict[int, list[tuple[int, int]]] = {}
        found = []
        for start, rows in completed(distinct_cells, {s: (reps[s:s + chunk],) for s in range(0, len(reps), chunk)},
                                     **backend):
            held[start] = [(mask, masked) for mask, masked, _ in rows.tolist()]
            found.append(rows)
            self._report("cells", len(reps[start:start + chunk]))
        rows = np.concatenate(found) if found else np.zeros((0, 3), dtype=np.int64)
        _, first = np.unique(rows[:, :2], axis=0, return_index=True)
        distinct = [tuple(row) for row in rows[first].tolist()]
        del found, rows
        tasks = {s: (distinct[s:s + _CELL_CHUNK], self.kept) for s in range(0, len(distinct), _CELL_CHUNK)}
        for start, part in completed(cell_texts, tasks, **backend):
            self._texts.update(((mask, masked), text) for (mask, masked, _), text in zip(tasks[start][0], part))
            self._report("elements", len(part))
        self._held = held

    def sample_entries(self, samples: int) -> list[str]:
        """The entry texts of about ``samples`` representatives spread over the whole table (after :meth:`cells`)."""
        codes = self.reps[::max(1, len(self.reps) // samples)]
        return [entry for _, entry in table_entries(codes, self._texts, self.criteria)]

    def chunks(self, finish: Callable[..., _T], *args: object) -> Iterator[_T]:
        """Pass 3 (after :meth:`cells`): ``finish(entries, *args)`` of every chunk, in code order, whatever
        order the workers finish in.  ``finish`` is a module-level function: workers import it by name."""
        reps, chunk, held = self.reps, self.chunk, self._held
        if held is None:
            raise RuntimeError("TableRun.chunks: run cells() first (it finds the cells the chunks use)")
        tasks = {s: (reps[s:s + chunk], {pair: self._texts[pair] for pair in held.pop(s)}, self.criteria, finish, *args)
                 for s in range(0, len(reps), chunk)}
        waiting, next_start = {}, 0
        for start, part in completed(_finished_chunk, tasks, **self._backend):
            waiting[start] = part
            while next_start in waiting:
                yield waiting.pop(next_start)
                self._report("entries", len(reps[next_start:next_start + chunk]))
                next_start += chunk
