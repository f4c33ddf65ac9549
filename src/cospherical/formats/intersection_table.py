"""The intersection study's pattern table: one entry per orbit representative, built from cells.

At 1/16 the table has 1.66 million entries; tessellating each again in Python
(1-4 ms) would take an hour.  But the entries are made of few distinct elements:
a cell is the same element, with the same pattern-table text under every
criterion, wherever its nodes sit at the same places.  So the table is built in
three passes:

1. **cells**: the compiled walk gives every representative's cells, each as (node
   mask, code masked to the digits its points depend on), as in the study's
   stage 1; the distinct pairs are collected (workers, in chunks).
2. **elements**: each distinct cell is classified, measured and split under every
   criterion's kept set once, by the exact Python path, and written as its
   pattern-table text (workers, in chunks): at 1/16 a few hundred thousand cells.
3. **entries**: the walk runs again on each chunk (workers, each given the texts
   of its chunk's cells) and every representative's line is joined from its
   cells' texts, exactly as :func:`~cospherical.formats.patterns.configuration_line`
   writes it from a tessellation (tested: the same bytes), and packed for the
   store there; this process writes the chunks in code order.

The YAML holds one line per configuration; from R = 8 on (1.9 GB and more,
beyond what :func:`~cospherical.formats.patterns.load` reads as YAML) the CLI
writes the indexed store alone unless asked for both.
"""

from __future__ import annotations

from collections.abc import Mapping
from contextlib import nullcontext
from dataclasses import dataclass

import numpy as np

from ..catalogue import kept_split, split_options
from ..core.element_types import classify
from ..core.symmetry import key_code
from ..core.tessellation import Element
from ..errors import InputError
from ..files.flowyaml import flow, mapping_text
from ..files.yamlio import atomic_open, yaml_text
from ..studies.intersection import cell_polyhedron, completed, orbits, tessellate_chunk
from ..version import __version__
from .patterns import SCHEMA_VERSION, element_entry
from .store import dictionary_of, pack, write_store

__all__ = ["SYMMETRY_CONVENTION", "YAML_UP_TO", "CellText", "cell_texts", "distinct_cells", "entry_chunk",
           "representative_cells", "table_entries", "write_pattern_table"]

SYMMETRY_CONVENTION = (
    "One entry per orbit of the cube's 48 symmetries. The representative is the configuration "
    "whose code, read as a base-16 number, is the smallest of its images; a symmetry sends the "
    "point at t on an edge to the image edge at t or, where the edge is reversed, at 1 - t. "
    "To use an entry for another configuration: cospherical.core.symmetry.orbit_representatives(codes, "
    "box_symmetries(cube)) gives each code's representative and the index of a symmetry taking it there; "
    "node n of the configuration is node node_map[n] of the representative under that symmetry (a "
    "reflection also reverses a VTK cell's node order). cospherical mesh --patterns does this "
    "(cospherical.formats.mesh.orbit_lookup).")
# The largest resolution whose table is also written as YAML by default: at R = 4 the
# YAML is 71 MB; at R = 8 1.9 GB, beyond the 512 MB the YAML reader accepts.
YAML_UP_TO = 4
CHUNK = 20_000
CELL_CHUNK = 2_000
SAMPLES = 16  # about 40 kB of entries at R = 8: the dictionary is their last 32 kB


def representative_cells(codes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per configuration (base-16 codes) its cell count, and per cell, in the walk's order, its
    node mask and masked code (see :func:`cospherical.core.compiled.cube_batch`)."""
    cells = tessellate_chunk(codes, every_cell=True)
    return cells["polys"], cells["poly_mask"], cells["poly_code"]


def distinct_cells(codes) -> np.ndarray:
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
        etype, order, mirrored = classify(poly)
        element = Element(etype, order, poly, mirrored)
        pieces = [(element,)]
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


def table_entries(codes, cells: Mapping[tuple[int, int], CellText], criteria: list[str]) -> list[tuple[str, str]]:
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
        written: dict[tuple, str] = {}
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


def entry_chunk(codes, cells: Mapping[tuple[int, int], CellText], criteria: list[str], yaml: bool,
                dictionary: bytes | None) -> tuple[str, list[tuple[str, bytes]]]:
    """Pass 3 on a chunk: its YAML lines (if ``yaml``) and its store rows (if a ``dictionary``)."""
    entries = table_entries(codes, cells, criteria)
    text = "".join(mapping_text(code, entry) for code, entry in entries) if yaml else ""
    return text, [] if dictionary is None else [(code, pack(entry, dictionary)) for code, entry in entries]


def write_pattern_table(summary: dict, catalogue_version: str, yaml_path=None, store=None, jobs: int = 1,
                        progress=None, scheduler: str | None = None, dask_workers: int | None = None,
                        chunk: int = CHUNK) -> None:
    """Write the pattern table of the study's orbit representatives (``summary`` gives the kept
    sets) as YAML at ``yaml_path`` and/or as an indexed store (:mod:`cospherical.formats.store`)
    at ``store``, from the same lines in one pass.

    ``progress(stage, n)`` as work finishes: ``cells`` and ``entries`` in representatives,
    ``elements`` in distinct cells.
    """
    resolution, order = summary["resolution"], summary["insertion_order"]
    reps, _, _ = orbits(resolution, order)
    kept = {c: data["kept"] for c, data in summary["criteria"].items() if c != "optimal"}
    criteria = ["optimal", *kept]
    header = {
        "schema_version": SCHEMA_VERSION, "generator": f"cospherical {__version__}",
        "catalogue_version": catalogue_version, "study": "intersection", "box": ["1", "1", "1"],
        "face_points": "octree",
        "scheme": f"midpoint scheme at multiples of 1/{resolution}, insertion order {order} (paper, section 5)",
        "symmetry": SYMMETRY_CONVENTION, "criteria": criteria,
    }
    report = progress or (lambda stage, n: None)
    backend = dict(jobs=jobs, scheduler=scheduler, dask_workers=dask_workers)
    starts = range(0, len(reps), chunk)

    # Pass 1: the distinct cells of each chunk, and of the whole table.
    held: dict[int, list[tuple[int, int]]] = {}
    found = []
    for start, rows in completed(distinct_cells, {s: (reps[s:s + chunk],) for s in starts}, **backend):
        held[start] = [(mask, masked) for mask, masked, _ in rows.tolist()]
        found.append(rows)
        report("cells", len(reps[start:start + chunk]))
    rows = np.concatenate(found) if found else np.zeros((0, 3), dtype=np.int64)
    _, first = np.unique(rows[:, :2], axis=0, return_index=True)
    distinct = [tuple(row) for row in rows[first].tolist()]
    del found, rows

    # Pass 2: each distinct cell's text, once.
    texts: dict[tuple[int, int], CellText] = {}
    tasks = {s: (distinct[s:s + CELL_CHUNK], kept) for s in range(0, len(distinct), CELL_CHUNK)}
    for start, part in completed(cell_texts, tasks, **backend):
        texts.update(((mask, masked), text) for (mask, masked, _), text in zip(tasks[start][0], part))
        report("elements", len(part))

    # Pass 3: the entries, each chunk with the texts of its own cells, written in code order.
    dictionary = None
    if store:  # the store's compression dictionary: entries spread over the whole table
        dictionary = dictionary_of([entry for _, entry in
                                    table_entries(reps[::max(1, len(reps) // SAMPLES)], texts, criteria)])
    tasks = {s: (reps[s:s + chunk], {pair: texts[pair] for pair in held.pop(s)}, criteria, bool(yaml_path), dictionary)
             for s in starts}

    def rows_in_order(handle):
        waiting, next_start = {}, 0
        for start, part in completed(entry_chunk, tasks, **backend):
            waiting[start] = part
            while next_start in waiting:  # in code order, whatever order the chunks finish in
                text, packed = waiting.pop(next_start)
                if handle:
                    handle.write(text)
                yield from packed
                report("entries", len(reps[next_start:next_start + chunk]))
                next_start += chunk

    with (atomic_open(yaml_path) if yaml_path else nullcontext()) as handle:
        if handle:
            handle.write(yaml_text(header) + "configurations:\n")
        if store:
            write_store(store, header, dictionary, rows_in_order(handle))
        else:
            for _ in rows_in_order(handle):
                pass
