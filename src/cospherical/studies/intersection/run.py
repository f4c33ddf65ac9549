"""Running the intersection study, in two stages that workers take in chunks.

1. **cells**: the compiled kernel tessellates every orbit representative and
   keeps, per configuration, its tetrahedra count, the circumcenter tests and
   each other cell as (node mask, code masked to the digits its points depend
   on): equal pairs are the same element at the same place.
2. **elements**: each distinct non-tetrahedral element is classified once, with
   its splits under every criterion (the exact Python path).

Each finished chunk can be checkpointed, so an interrupted run resumes; the
statistics (:mod:`.statistics`) then count every configuration through the orbit
sizes.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import os
import re
import stat
from dataclasses import asdict
from pathlib import Path
from typing import Any, Callable, TypeVar

import numpy as np

from ...caches import cached
from ...catalogue import option_types, split_options
from ...core.configuration import Configuration
from ...core.delaunay import delaunay_cells
from ...core.element_types import classify
from ...core.geometry import Frame
from ...core.polyhedron import Polyhedron, polyhedron
from ...core.shapes import Point
from ...choices import SPLIT_CRITERIA
from ...core.symmetry import key_code
from ...execution.backends import Backend, completed
from ...files.yamlio import atomic_write, parse_json
from ..summary import TypeInfo
from .family import all_configurations, orbits
from .statistics import ElementEntry, statistics

__all__ = ["CHUNK", "ELEMENT_CHUNK", "cell_polyhedron", "element_entries", "example_elements", "run_intersection",
           "tessellate_chunk"]

_T = TypeVar("_T")
# Stage 2 on some elements: their entries, and every type met (pieces included), described.
ElementStage = tuple[list[ElementEntry], dict[str, TypeInfo]]
# What run_intersection collects per type: (node mask, code) of an element of that type, or
# (node mask, code, criterion) of one whose split under that criterion has a piece of that type.
Example = tuple[int, int] | tuple[int, int, str]

CHUNK = 5000
ELEMENT_CHUNK = 500
# Bumped when a checkpoint's content changes, so --resume never reads an older layout.
_CHECKPOINT_FORMAT = 3
_CELLS_PER_CONFIGURATION = 96  # the compiled walk's room per configuration, tetrahedra included


@cached(maxsize=1)
def _cube_tables() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    # The compiled kernel (numba) is imported only where bulk work needs it: the
    # command line starts without it.
    from ...core import compiled

    return compiled.cube_tables()


def tessellate_chunk(codes: np.ndarray, every_cell: bool = False) -> dict[str, np.ndarray]:
    """Stage 1 on base-16 codes: per configuration ``tets``, ``closed``, ``open``, ``polys``;
    per other cell ``poly_mask`` and ``poly_code`` (see :func:`cospherical.core.compiled.cube_batch`).
    ``every_cell``: tetrahedra too, in ``polys`` and the cell lists (what a pattern table needs)."""
    from ...core import compiled

    codes = np.ascontiguousarray(codes, dtype=np.int64)
    n = len(codes)
    tets, polys = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    closed, open_ = np.empty(n, dtype=np.bool_), np.empty(n, dtype=np.bool_)
    # A cell other than a tetrahedron has at least five of the at most 27 points, so 27 per
    # configuration is ample; with tetrahedra, 96 (27 measured at most at 1/16). Beyond, an error.
    room = (_CELLS_PER_CONFIGURATION if every_cell else 27) * n
    poly_mask, poly_code = np.empty(room, dtype=np.int64), np.empty(room, dtype=np.int64)
    written = compiled.cube_batch(codes, *_cube_tables(), tets, closed, open_, polys, poly_mask, poly_code, every_cell)
    if written < 0:
        raise RuntimeError(f"configuration {codes[-1 - written]:012x}: beyond the compiled walk's buffers")
    return {"tets": tets, "closed": closed, "open": open_, "polys": polys,
            "poly_mask": poly_mask[:written], "poly_code": poly_code[:written]}


class NotACell(ValueError):
    """Stage 1 named a cell, (node mask, configuration code), whose points are not one co-spherical
    cell of that configuration.  The tessellation names only cells: such a name comes from a
    stage-1 checkpoint changed with its checksum renewed, whose values are each in range."""

    def __init__(self, node_mask: int, code: int):
        super().__init__(node_mask, code)  # the arguments again: a worker's error is pickled
        self.node_mask, self.code = node_mask, code

    def __str__(self) -> str:
        return f"node mask {self.node_mask:#x} of configuration {key_code(self.code)} is not one cell"


def cell_polyhedron(node_mask: int, code: int,
                    of_configuration: bool = True) -> tuple[tuple[tuple[int, Point], ...], Polyhedron]:
    """A cell named as stage 1 names it, (node mask, a configuration code holding it), as
    ``(points, polyhedron)``: its (node, unit coordinates) pairs and its exact polyhedron.

    A name whose points are not one co-spherical cell, or (``of_configuration``) not a
    Delaunay cell of that configuration, raises :class:`NotACell`.  Only the tetrahedron's
    representative (:func:`_tetrahedron`: four corners of the cube) is not the latter."""
    nodes = Configuration.from_code(key_code(code)).nodes()
    if node_mask & ~sum(1 << n for n in nodes):  # a node the configuration does not have
        raise NotACell(node_mask, code)
    points = tuple((n, nodes[n]) for n in sorted(nodes) if node_mask >> n & 1)
    frame = Frame.build(dict(points), (1, 1, 1))
    try:
        cells = delaunay_cells(frame, "compiled")  # co-spherical points: one cell; the study's bulk walk
    except ValueError:  # delaunay_cells' refusal of points that do not span 3D
        raise NotACell(node_mask, code) from None
    if len(cells) != 1:
        raise NotACell(node_mask, code)
    # and a cell of the configuration: its sphere holds no other node of it, inside or on it (unit cube):
    # |p - c|^2 <= |p0 - c|^2, that is |p|^2 - 2 p.c <= |p0|^2 - 2 p0.c, in integers over a common
    # denominator of every coordinate (a Fraction per coordinate cost a third of the element stage)
    if of_configuration:
        center = cells[0].center
        den = math.lcm(*(x.denominator for x in center), *(x.denominator for p in nodes.values() for x in p))
        c = [x.numerator * (den // x.denominator) for x in center]

        def power(point: Point) -> int:  # (|p|^2 - 2 p.c) * den^2
            q = [x.numerator * (den // x.denominator) for x in point]
            return q[0] * (q[0] - 2 * c[0]) + q[1] * (q[1] - 2 * c[1]) + q[2] * (q[2] - 2 * c[2])

        radius = power(points[0][1])
        if any(power(point) <= radius for n, point in nodes.items() if not node_mask >> n & 1):
            raise NotACell(node_mask, code)
    return points, polyhedron(frame, cells[0])


def element_entries(elements: list[tuple[int, int]],
                    of_configuration: bool = True) -> tuple[list[ElementEntry], dict[str, TypeInfo]]:
    """Stage 2: per (node mask, code of a configuration holding it), the element's
    :class:`ElementEntry`; and every type met (pieces included), described
    (``of_configuration``: as for :func:`cell_polyhedron`)."""
    squared = (1, 1, 1)
    entries: list[ElementEntry] = []
    types: dict[str, TypeInfo] = {}
    for node_mask, code in elements:
        points, poly = cell_polyhedron(node_mask, code, of_configuration)
        etype = classify(poly)[0]
        types.setdefault(etype.id, TypeInfo.of(etype))
        options: dict[str, tuple[tuple[str, ...], ...]] = {}
        for criterion in SPLIT_CRITERIA:
            found = split_options(points, squared, poly, criterion)
            for piece in (piece for option in found for piece in option):
                types.setdefault(piece.type.id, TypeInfo.of(piece.type))
            options[criterion] = tuple(dict.fromkeys(option_types(o) for o in found))
        entries.append(ElementEntry(etype.id, options))
    return entries, types


def _element_chunk_json(part: ElementStage) -> str:
    entries, types = part
    return json.dumps([[asdict(e) for e in entries], {k: asdict(t) for k, t in types.items()}], sort_keys=True)


# A checkpoint is one line naming the SHA-256 of its content, then the content: a file
# damaged in any byte fails the sum and is computed again, never counted.
_CHECKSUM = re.compile(rb"cospherical checkpoint sha256 ([0-9a-f]{64})\n")
_ALL_NODES = (1 << 27) - 1
# Bytes of a checkpoint per unit, far above what is written (stage 1: 18 bytes per configuration
# and 16 per cell; stage 2: about 1 kB per element), so that a damaged file is never read whole.
_CELL_BYTES = 18 + 16 * _CELLS_PER_CONFIGURATION
_ELEMENT_BYTES = 64 * 1024


def _checkpoint_bytes(payload: bytes) -> bytes:
    return b"cospherical checkpoint sha256 %s\n" % hashlib.sha256(payload).hexdigest().encode() + payload


def _checked_payload(path: Path, most: int) -> bytes:
    """A checkpoint's content after its checksum, at most ``most`` bytes; ValueError says why not."""
    # opened without blocking, then required to be a regular file: a FIFO put in a checkpoint's place
    # would block open() or read() for ever
    descriptor = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    with open(descriptor, "rb") as handle:
        if not stat.S_ISREG(os.fstat(descriptor).st_mode):
            raise ValueError("not a regular file")
        data = handle.read(most + 100)
    if len(data) > most + 100:
        raise ValueError(f"over {most:,} bytes")
    found = _CHECKSUM.match(data)
    if found is None:
        raise ValueError("no checksum line")
    payload = data[found.end():]
    if hashlib.sha256(payload).hexdigest().encode() != found.group(1):
        raise ValueError("its checksum does not match its content")
    return payload


CELL_NAMES = ("tets", "closed", "open", "polys", "poly_mask", "poly_code")


def _read_cells(path: Path, count: int) -> dict[str, np.ndarray]:
    """A stage-1 checkpoint of ``count`` configurations, checked (checksum, sizes before reading, every
    value in its range); ValueError says why it cannot be used."""
    import zipfile

    payload = _checked_payload(path, 4096 + _CELL_BYTES * count)
    try:
        with zipfile.ZipFile(io.BytesIO(payload)) as archive:
            # stored, never deflated: what an array claims is what the file holds
            members = {info.filename: info for info in archive.infolist()}
            if set(members) != {f"{name}.npy" for name in CELL_NAMES} or any(
                    info.compress_type != zipfile.ZIP_STORED for info in members.values()):
                raise ValueError("not the arrays of a stage-1 checkpoint")
            for info in members.values():  # an array's header must not claim more than its member holds
                with archive.open(info) as member:
                    version = np.lib.format.read_magic(member)
                    header = np.lib.format.read_array_header_1_0 if version == (1, 0) \
                        else np.lib.format.read_array_header_2_0
                    shape, _, dtype = header(member)
                if len(shape) != 1 or shape[0] * dtype.itemsize > info.file_size:
                    raise ValueError(f"{info.filename} claims {shape} of {dtype}, more than it holds")
        with np.load(io.BytesIO(payload), allow_pickle=False) as data:
            part = {name: data[name] for name in CELL_NAMES}
    except (OSError, KeyError, EOFError, zipfile.BadZipFile) as error:
        raise ValueError(f"not a readable archive ({error})") from None
    if any(part[name].ndim != 1 for name in CELL_NAMES) or any(len(part[name]) != count for name in CELL_NAMES[:4]):
        raise ValueError(f"not arrays of {count} configurations")
    if part["closed"].dtype != np.bool_ or part["open"].dtype != np.bool_ \
            or any(part[name].dtype != np.int64 for name in ("tets", "polys", "poly_mask", "poly_code")):
        raise ValueError("arrays of the wrong types")
    tets, polys, mask, code = part["tets"], part["polys"], part["poly_mask"], part["poly_code"]
    if tets.min(initial=0) < 0 or polys.min(initial=0) < 0 \
            or (tets + polys).max(initial=0) > _CELLS_PER_CONFIGURATION or len(mask) != len(code) \
            or len(mask) != int(polys.sum()) or mask.min(initial=1) < 1 or mask.max(initial=0) > _ALL_NODES \
            or code.min(initial=0) < 0 or code.max(initial=0) >= 16**12:
        raise ValueError("counts or cells out of range")
    return part


def _read_elements(path: Path, count: int) -> ElementStage:
    """A stage-2 checkpoint of ``count`` elements, checked: ``(entries, types)``; ValueError says why not."""
    text = _checked_payload(path, 4096 + _ELEMENT_BYTES * count).decode("utf-8")
    data = parse_json(text, path.name)
    try:
        entries, types = data
        entries = [ElementEntry.from_json(e) for e in entries]
        types = {k: TypeInfo(**t) for k, t in types.items()}
    except (ValueError, TypeError, KeyError, AttributeError) as error:
        raise ValueError(f"not a stage-2 checkpoint ({type(error).__name__})") from None
    if len(entries) != count:
        raise ValueError(f"{len(entries)} entries for {count} elements")
    for entry in entries:
        named = [entry.type, *(piece for options in entry.options.values() for option in options for piece in option)]
        if set(entry.options) != set(SPLIT_CRITERIA) or any(not isinstance(t, str) or t not in types for t in named):
            raise ValueError(f"an entry of type {str(entry.type)[:40]!r} names criteria or types it does not hold")
    return entries, types


def _resumed(read: Callable[[Path, int], _T], path: Path, count: int, damaged: list[str]) -> _T | None:
    """A checkpoint's content, or ``None`` when it is missing or damaged (noted in ``damaged``)."""
    if not path.exists():
        return None
    try:
        return read(path, count)
    except (OSError, ValueError, UnicodeDecodeError) as error:
        damaged.append(f"{path.name} ({str(error).splitlines()[0][:80]})")
        return None


def _npz_bytes(arrays: dict[str, np.ndarray]) -> bytes:
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)  # type: ignore[arg-type]  # numpy's stub takes a name for allow_pickle's
    return buffer.getvalue()


def _tetrahedron() -> ElementStage:
    """The entry of the tetrahedron (every 4-point cell has this one type; no split)."""
    corners = (0, 1, 3, 4)  # of the cube with no Steiner point (code 0)
    return element_entries([(sum(1 << n for n in corners), 0)], of_configuration=False)


def run_intersection(resolution: int = 16, order: str = "edge", jobs: int = 1, checkpoints: str | Path | None = None,
                     progress: Callable[[str, int], None] | None = None, chunk: int = CHUNK, scheduler: str | None = None,
                     dask_workers: int | None = None, brute_force: bool = False,
                     examples: dict[str, Example] | None = None,
                     notice: Callable[[str], None] | None = None) -> dict[str, Any]:
    """The intersection study's summary, all criteria, in the shape of the bisection study's.

    Parameters
    ----------
    resolution, order : int, str
        Steiner points at multiples of 1/resolution, levels inserted in this order
        (:data:`~.family.INSERTION_ORDERS`).
    jobs : int
        Local worker processes.
    checkpoints : path, optional
        A folder keeping each finished chunk; chunks found there are not computed
        again, so an interrupted run resumes.  Each carries the SHA-256 of its
        content; one whose sum, size or values fail is computed again (and
        rewritten), never counted.
    progress : callable, optional
        ``progress(stage, n)`` as work finishes: ``cells`` in configurations,
        ``elements`` in distinct elements.
    scheduler, dask_workers : optional
        Run the chunks on Dask (a scheduler address, or a local cluster of that
        many processes) instead of ``jobs`` local processes.
    brute_force : bool
        Tessellate every configuration, not one per orbit (a check).
    examples : dict, optional
        Filled with an example of every type met: type id -> ``(node mask, code)``
        of an element of that type, or ``(node mask, code, criterion)`` of an
        element one of whose splits under that criterion has a piece of that type
        (see :func:`example_elements`).
    notice : callable, optional
        ``notice(line)``: one line per stage naming the damaged checkpoints computed again.

    Returns
    -------
    dict
        The summary (``study``, ``box``, ``resolution``, ``insertion_order``,
        ``configurations``, ``orbits``, ``fvm_adequate``, ``fvm_adequate_open``,
        ``criteria``).
    """
    if brute_force:
        reps = all_configurations(resolution, order)
        sizes, configurations = np.ones(len(reps), dtype=np.int64), len(reps)
    else:
        reps, sizes, configurations = orbits(resolution, order)
    folder = Path(checkpoints) if checkpoints else None
    tag = f"v{_CHECKPOINT_FORMAT}-r{resolution}-{order}-c{chunk}{'-brute' if brute_force else ''}"
    if folder:
        folder.mkdir(parents=True, exist_ok=True)
    backend = Backend(jobs=jobs, scheduler=scheduler, dask_workers=dask_workers)
    report = progress or (lambda stage, n: None)

    # Stage 1: cells.
    starts = range(0, len(reps), chunk)
    stage1: dict[int, dict[str, np.ndarray]] = {}
    resumed: set[int] = set()  # the stage-1 chunks read from checkpoints: what stage 2 may find not cells
    damaged: list[str] = []
    for i, start in enumerate(starts):
        part = _resumed(_read_cells, folder / f"{tag}-cells-{i:05d}.npz", len(reps[start:start + chunk]),
                        damaged) if folder else None
        if part is not None:
            stage1[i] = part
            resumed.add(i)
            report("cells", int(sizes[start:start + chunk].sum()))
    _notice(notice, damaged)

    def tessellate_missing() -> None:
        todo = {i: (reps[start:start + chunk],) for i, start in enumerate(starts) if i not in stage1}
        for i, part in completed(tessellate_chunk, todo, **backend):
            stage1[i] = part
            if folder:
                atomic_write(folder / f"{tag}-cells-{i:05d}.npz", _checkpoint_bytes(_npz_bytes(part)))
            report("cells", int(sizes[i * chunk:(i + 1) * chunk].sum()))

    tessellate_missing()
    while True:
        cells = {name: np.concatenate([stage1[i][name] for i in range(len(starts))]) if starts
                 else np.zeros(0, np.int64) for name in ("tets", "closed", "open", "polys", "poly_mask", "poly_code")}
        # Stage 2: every distinct non-tetrahedral element, once.
        pairs = np.stack([cells["poly_mask"], cells["poly_code"]], axis=1)
        distinct, first, element_of = np.unique(pairs, axis=0, return_index=True, return_inverse=True)
        element_of = element_of.reshape(-1)
        holder = np.repeat(np.arange(len(reps)), cells["polys"])[first]  # a configuration holding each element
        work = [(int(mask), int(code)) for (mask, _), code in zip(distinct.tolist(), np.asarray(reps)[holder].tolist())]
        try:
            entries, types = _element_stage(work, folder, tag, backend, report, notice)
            break
        except NotACell as error:
            # a stage-1 checkpoint named it (the tessellation names only cells): that chunk is damaged
            position = {element: k for k, element in enumerate(work)}.get((error.node_mask, error.code))
            damaged_chunk = None if position is None else int(holder[position]) // chunk
            if damaged_chunk not in resumed:
                raise
            _notice(notice, [f"{tag}-cells-{damaged_chunk:05d}.npz ({error})"])
            del stage1[damaged_chunk]
            resumed.discard(damaged_chunk)
            tessellate_missing()
    if examples is not None:
        tetrahedron = (sum(1 << n for n in (0, 1, 3, 4)), 0)  # as _tetrahedron() makes it
        for (mask, code), entry in zip([tetrahedron, *work], entries):
            examples.setdefault(entry.type, (mask, code))
            for criterion, options in entry.options.items():
                for piece in (piece for option in options for piece in option):
                    examples.setdefault(piece, (mask, code, criterion))
    return {
        "study": "intersection", "box": ["1", "1", "1"], "face_points": "octree",
        "resolution": resolution, "insertion_order": order,
        "configurations": configurations, "orbits": len(reps),
        **statistics(sizes, cells, element_of + 1, entries, types),
    }


def _element_stage(work: list[tuple[int, int]], folder: Path | None, tag: str, backend: Backend,
                   report: Callable[[str, int], None], notice: Callable[[str], None] | None) -> ElementStage:
    """Stage 2 of :func:`run_intersection`: the entries of ``work`` (after the tetrahedron's) and the types.

    Its checkpoints are named by a digest of ``work``: they are the entries of these elements
    only, never reused for another stage 1 (one whose damaged checkpoint was computed again).
    """
    digest = hashlib.sha256(json.dumps(work).encode()).hexdigest()[:16]
    element_starts = range(0, len(work), ELEMENT_CHUNK)
    stage2: dict[int, ElementStage] = {}
    damaged: list[str] = []
    for i, start in enumerate(element_starts):
        part = _resumed(_read_elements, folder / f"{tag}-w{digest}-elements-{i:05d}.json",
                        len(work[start:start + ELEMENT_CHUNK]), damaged) if folder else None
        if part is not None:
            stage2[i] = part
            report("elements", len(part[0]))
    _notice(notice, damaged)
    todo = {i: (work[start:start + ELEMENT_CHUNK],) for i, start in enumerate(element_starts) if i not in stage2}
    written: list[Path] = []
    try:
        for i, part in completed(element_entries, todo, **backend):
            stage2[i] = part
            if folder:
                written.append(folder / f"{tag}-w{digest}-elements-{i:05d}.json")
                atomic_write(written[-1], _checkpoint_bytes(_element_chunk_json(part).encode("utf-8")))
            report("elements", len(part[0]))
    except NotACell:  # this work is abandoned: its checkpoints would only ever be stale
        for path in written:
            path.unlink(missing_ok=True)
        raise
    entries, types = _tetrahedron()
    for i in range(len(element_starts)):
        entries.extend(stage2[i][0])
        types.update(stage2[i][1])
    return entries, types


def _notice(notice: Callable[[str], None] | None, damaged: list[str]) -> None:
    if damaged and notice is not None:
        more = f" and {len(damaged) - 1} more" if len(damaged) > 1 else ""
        notice(f"damaged checkpoint {damaged[0]}{more}: computed again")


def example_elements(examples: dict[str, Example]) -> dict[str, tuple[str, tuple[int, ...]]]:
    """The examples :func:`run_intersection` collects as type id -> (configuration code, node ids).

    A piece type's example is a piece of its parent element's splits with that type.
    """
    squared = (1, 1, 1)
    found = {}
    for type_id, example in examples.items():
        mask, code = example[:2]
        points, poly = cell_polyhedron(mask, code, of_configuration=False)  # the tetrahedron's example too
        if len(example) == 2:
            found[type_id] = (key_code(code), tuple(n for n, _ in points))
            continue
        options = split_options(points, squared, poly, example[2])
        piece = next(p for option in options for p in option if p.type.id == type_id)
        found[type_id] = (key_code(code), piece.polyhedron.nodes)
    return found
