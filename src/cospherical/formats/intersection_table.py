"""The intersection study's pattern table, written: YAML and/or the indexed store, from the same lines.

The entries are computed by :class:`cospherical.studies.intersection.table.TableRun`
(three passes over cells, see there); this module writes its header and lines.
The YAML holds one line per configuration; from R = 8 on (1.9 GB and more,
beyond what :func:`~cospherical.formats.patterns.load` reads as YAML) the CLI
writes the indexed store alone unless asked for both.
"""

from __future__ import annotations

from contextlib import nullcontext
from pathlib import Path
from typing import IO, Any, Callable, Iterator, Protocol, TypeVar

from ..files.flowyaml import mapping_text
from ..files.yamlio import atomic_open, yaml_text
from ..version import __version__
from .patterns import SCHEMA_VERSION
from .sqlite_store import dictionary_of, pack, write_store

_T = TypeVar("_T")


class TableRun(Protocol):
    """What the writer reads of the study's run (:class:`cospherical.studies.intersection.table.TableRun`,
    which the formats do not import: they read and write, the studies compute)."""

    resolution: int
    order: str
    criteria: list[str]

    def cells(self) -> None: ...
    def sample_entries(self, samples: int) -> list[str]: ...
    def chunks(self, finish: Callable[..., _T], *args: object) -> Iterator[_T]: ...

__all__ = ["SYMMETRY_CONVENTION", "YAML_UP_TO", "entry_chunk", "write_pattern_table"]

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
_SAMPLES = 16  # about 40 kB of entries at R = 8: the dictionary is their last 32 kB


def entry_chunk(entries: list[tuple[str, str]], yaml: bool, dictionary: bytes | None) -> tuple[str, list[tuple[str, bytes]]]:
    """A chunk's entries (code, entry JSON) as its YAML lines (if ``yaml``) and its store rows (if a
    ``dictionary``): run in the workers of pass 3."""
    text = "".join(mapping_text(code, entry) for code, entry in entries) if yaml else ""
    return text, [] if dictionary is None else [(code, pack(entry, dictionary)) for code, entry in entries]


def write_pattern_table(run: TableRun, catalogue_version: str, yaml_path: str | Path | None = None,
                        store: str | Path | None = None) -> None:
    """Write the pattern table that ``run`` computes (a
    :class:`~cospherical.studies.intersection.table.TableRun`: the study's orbit representatives
    and kept sets) as YAML at ``yaml_path`` and/or as an indexed store
    (:mod:`cospherical.formats.sqlite_store`) at ``store``, from the same lines in one pass.
    """
    header = {
        "schema_version": SCHEMA_VERSION, "generator": f"cospherical {__version__}",
        "catalogue_version": catalogue_version, "study": "intersection", "box": ["1", "1", "1"],
        "face_points": "octree",
        "scheme": f"midpoint scheme at multiples of 1/{run.resolution}, insertion order {run.order} (paper, section 5)",
        "symmetry": SYMMETRY_CONVENTION, "criteria": run.criteria,
    }
    run.cells()
    # the store's compression dictionary: entries spread over the whole table
    dictionary = dictionary_of(run.sample_entries(_SAMPLES)) if store else None

    def rows_in_order(handle: IO[Any] | None) -> Iterator[tuple[str, bytes]]:
        for text, packed in run.chunks(entry_chunk, bool(yaml_path), dictionary):
            if handle:
                handle.write(text)
            yield from packed

    with (atomic_open(yaml_path) if yaml_path else nullcontext()) as handle:
        if handle:
            handle.write(yaml_text(header) + "configurations:\n")
        if store and dictionary is not None:  # made above exactly when there is a store
            write_store(store, header, dictionary, rows_in_order(handle))
        else:
            for _ in rows_in_order(handle):
                pass
