"""The intersection family (paper, section 5): Steiner points anywhere, at multiples of 1/R.

For each of the three sets of four parallel edges, a *pattern* says which edges
carry a point and the relative order of those points, ties allowed (an ordered
partition of the points into levels).  The paper's midpoint scheme turns levels
into positions: the first level inserted goes to 1/2; a level left of every
placed one goes halfway between 0 and the leftmost; right of every placed one,
halfway between the rightmost and 1; between two placed ones, halfway between
them.  The paper does not say in which order the levels are inserted, so the
order is a parameter:

``edge``      levels in the order their first point appears along the edge list;
``rank``      from the lowest level up;
``reverse``   from the highest level down.

m levels need positions down to 1/2^m, so at resolution R = 2^d only patterns
with at most d levels exist; at R = 16 every pattern (150 per set) does.
"""

from __future__ import annotations

from fractions import Fraction
from itertools import combinations, product

import numpy as np

from ..core.configuration import edge_axis
from ..core.split import SPLIT_CRITERIA

__all__ = ["INSERTION_ORDERS", "PARALLEL_EDGES", "intersection_codes", "set_patterns"]

INSERTION_ORDERS = ("edge", "rank", "reverse")
PARALLEL_EDGES = tuple(tuple(k for k in range(12) if edge_axis(k) == axis) for axis in range(3))


def _ordered_partitions(k: int):
    """Every surjection of k points onto levels 0..m-1 (weak orders of k items)."""
    for m in range(1, k + 1):
        for levels in product(range(m), repeat=k):
            if len(set(levels)) == m:
                yield levels


def _positions(levels: tuple[int, ...], order: str) -> dict[int, Fraction]:
    m = max(levels) + 1
    if order == "edge":
        sequence = list(dict.fromkeys(levels))
    elif order == "rank":
        sequence = list(range(m))
    elif order == "reverse":
        sequence = list(range(m - 1, -1, -1))
    else:
        raise ValueError(f"insertion order {order!r}: choose one of {', '.join(INSERTION_ORDERS)}")
    placed: dict[int, Fraction] = {}
    for level in sequence:
        below = [placed[l] for l in placed if l < level]
        above = [placed[l] for l in placed if l > level]
        low = max(below) if below else Fraction(0)
        high = min(above) if above else Fraction(1)
        placed[level] = (low + high) / 2
    return placed


def set_patterns(resolution: int = 16, order: str = "edge") -> list[tuple[int, int, int, int]]:
    """Every pattern of one set of four parallel edges, as 16ths (0 = no point), sorted.

    >>> len(set_patterns(16)), len(set_patterns(2))
    (150, 16)
    """
    if resolution < 2 or resolution & (resolution - 1) or resolution > 16:
        raise ValueError(f"resolution {resolution}: a power of two from 2 to 16")
    depth = resolution.bit_length() - 1
    patterns = set()
    for k in range(5):
        for carriers in combinations(range(4), k):
            for levels in _ordered_partitions(k) if k else [()]:
                if levels and max(levels) + 1 > depth:
                    continue
                digits = [0, 0, 0, 0]
                if levels:
                    where = _positions(levels, order)
                    for edge, level in zip(carriers, levels):
                        digits[edge] = int(where[level] * 16)
                patterns.add(tuple(digits))
    return sorted(patterns)


def intersection_codes(resolution: int = 16, order: str = "edge") -> np.ndarray:
    """All configurations as an (N, 12) array of hex digits, one row per configuration code."""
    patterns = np.array(set_patterns(resolution, order), dtype=np.uint8)
    n = len(patterns)
    grid = np.zeros((n, n, n, 12), dtype=np.uint8)
    for axis, edges in enumerate(PARALLEL_EDGES):
        shape = [1, 1, 1, 4]
        shape[axis] = n
        view = patterns.reshape(shape)
        grid[..., list(edges)] = view
    return grid.reshape(-1, 12)


# ---------------------------------------------------------------------------
# Running the study, in two stages that worker processes (or Dask workers) take
# in chunks, each chunk checkpointed so that an interrupted run resumes:
#
# 1. cells: the compiled kernel tessellates every orbit representative and
#    keeps, per configuration, its tetrahedra count, the circumcenter tests and
#    each other cell as (node mask, code masked to the digits its points depend
#    on): equal pairs are the same element at the same place.
# 2. elements: each distinct non-tetrahedral element is classified once, with
#    its splits under every criterion (the exact Python path).
#
# The statistics then count every configuration through the orbit sizes.

CHUNK = 5000
ELEMENT_CHUNK = 500


def orbits(resolution: int = 16, order: str = "edge") -> tuple[np.ndarray, np.ndarray, int]:
    """Orbit representatives (codes as base-16 numbers, sorted) with their sizes, and the configuration count.

    The family is not closed under the cube's symmetries (a reflected configuration
    has positions 1 - t, which the midpoint scheme does not produce), so an orbit
    here collects only the family's members that map onto each other.
    """
    from ..core.configuration import Box
    from ..core.symmetry import box_symmetries, orbit_keys

    digits = intersection_codes(resolution, order)
    keys, _ = orbit_keys(digits, box_symmetries(Box.parse(["1", "1", "1"])))
    reps, sizes = np.unique(keys, return_counts=True)
    return reps, sizes, len(digits)


def all_configurations(resolution: int = 16, order: str = "edge") -> np.ndarray:
    """Every configuration's code as a base-16 number, sorted (the brute-force run, no orbits)."""
    digits = intersection_codes(resolution, order).astype(np.int64)
    return np.sort((digits << (4 * np.arange(11, -1, -1))).sum(axis=1))


def tessellate_chunk(codes: np.ndarray) -> dict[str, np.ndarray]:
    """Stage 1 on base-16 codes: per configuration ``tets``, ``closed``, ``open``, ``polys``;
    per other cell ``poly_mask`` and ``poly_code`` (see :func:`cospherical.compiled.cube_batch`)."""
    from ..core import compiled

    codes = np.ascontiguousarray(codes, dtype=np.int64)
    n = len(codes)
    tets, polys = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    closed, open_ = np.empty(n, dtype=np.bool_), np.empty(n, dtype=np.bool_)
    # A cell has at least four of the at most 27 points, so 27 other cells per configuration is ample.
    poly_mask, poly_code = np.empty(27 * n, dtype=np.int64), np.empty(27 * n, dtype=np.int64)
    written = compiled.cube_batch(codes, *_cube_tables(), tets, closed, open_, polys, poly_mask, poly_code)
    if written < 0:
        raise RuntimeError(f"configuration {codes[-1 - written]:012x}: beyond the compiled walk's buffers")
    return {"tets": tets, "closed": closed, "open": open_, "polys": polys,
            "poly_mask": poly_mask[:written], "poly_code": poly_code[:written]}


_TABLES = None


def _cube_tables():
    global _TABLES
    if _TABLES is None:
        from ..core.compiled import _cube_tables as tables

        _TABLES = tables()
    return _TABLES


def element_entries(elements: list[tuple[int, int]]) -> tuple[list[list], dict[str, list]]:
    """Stage 2: per (node mask, code of a configuration holding it), the element's type id and,
    per split criterion, its options as type-id tuples (the element itself first, in the order
    :func:`cospherical.criteria.split_options` prefers them); and the types met, described."""
    from ..catalogue import split_options
    from ..core.configuration import Configuration
    from ..core.delaunay import delaunay_cells
    from ..core.element_types import classify
    from ..core.geometry import Frame
    from ..core.polyhedron import polyhedron
    from ..core.symmetry import key_code

    squared = (1, 1, 1)
    entries, types = [], {}
    for node_mask, code in elements:
        nodes = Configuration.from_code(key_code(code)).nodes()
        points = tuple((n, nodes[n]) for n in sorted(nodes) if node_mask >> n & 1)
        frame = Frame.build(dict(points), squared)
        (cell,) = delaunay_cells(frame)  # the points are co-spherical: one cell
        poly = polyhedron(frame, cell)
        etype = classify(poly)[0]
        entry = [etype.id]
        _describe(etype, types)
        for criterion in SPLIT_CRITERIA:
            options = split_options(points, squared, poly, criterion)
            for option in options:
                for piece in option:
                    _describe(piece.type, types)
            entry.append(list(dict.fromkeys(tuple(sorted(p.type.id for p in o)) for o in options)))
        entries.append(entry)
    return entries, types


def _describe(etype, types: dict) -> None:
    if etype.id not in types:
        from ..catalogue import type_name
        from ..paper import paper_class

        types[etype.id] = [type_name(etype), etype.vertices, etype.edges, etype.faces, (paper_class(etype) or {}).get("name")]


def _tetrahedron():
    """The entry of the tetrahedron (every 4-point cell has this one type; no split)."""
    corners = (0, 1, 3, 4)  # of the cube with no Steiner point (code 0)
    return element_entries([(sum(1 << n for n in corners), 0)])


def _completed(function, tasks: dict, jobs: int, scheduler: str | None, dask_workers: int | None):
    """Yield ``(key, function(*args))`` for every task, as they finish, on the chosen backend."""
    if scheduler or dask_workers:
        from dask.distributed import Client, LocalCluster, as_completed

        cluster = None if scheduler else LocalCluster(n_workers=dask_workers, threads_per_worker=1,
                                                      processes=True, dashboard_address=None)
        client = Client(scheduler or cluster)
        try:
            futures = {client.submit(function, *args, pure=False): key for key, args in tasks.items()}
            for future in as_completed(futures):
                yield futures[future], future.result()
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    elif jobs <= 1:
        for key, args in tasks.items():
            yield key, function(*args)
    else:
        from concurrent.futures import ProcessPoolExecutor, as_completed

        pool = ProcessPoolExecutor(max_workers=jobs)
        try:
            futures = {pool.submit(function, *args): key for key, args in tasks.items()}
            for future in as_completed(futures):
                yield futures[future], future.result()
        finally:
            pool.shutdown(wait=True, cancel_futures=True)


def run_intersection(resolution: int = 16, order: str = "edge", jobs: int = 1, checkpoints=None,
                     progress=None, chunk: int = CHUNK, scheduler: str | None = None,
                     dask_workers: int | None = None, brute_force: bool = False) -> dict:
    """The intersection study's summary, all criteria, in the shape of the bisection study's.

    ``checkpoints``: a folder keeping each finished chunk; chunks found there are
    not computed again, so an interrupted run resumes.  ``scheduler`` (a Dask
    scheduler address) or ``dask_workers`` (a local Dask cluster of that many
    processes) run the chunks on Dask instead of ``jobs`` local processes.
    ``brute_force``: tessellate every configuration, not one per orbit (a check).
    ``progress(stage, n)`` is told as work finishes: ``cells`` in configurations,
    ``elements`` in distinct elements.
    """
    import json
    from pathlib import Path

    from ..files.yamlio import atomic_write

    if brute_force:
        reps = all_configurations(resolution, order)
        sizes, configurations = np.ones(len(reps), dtype=np.int64), len(reps)
    else:
        reps, sizes, configurations = orbits(resolution, order)
    folder = Path(checkpoints) if checkpoints else None
    tag = f"r{resolution}-{order}-c{chunk}{'-brute' if brute_force else ''}"
    if folder:
        folder.mkdir(parents=True, exist_ok=True)
    backend = dict(jobs=jobs, scheduler=scheduler, dask_workers=dask_workers)
    report = progress or (lambda stage, n: None)

    # Stage 1: cells.
    starts = range(0, len(reps), chunk)
    stage1: dict[int, dict] = {}
    for i, start in enumerate(starts):
        path = folder / f"{tag}-cells-{i:05d}.npz" if folder else None
        if path and path.exists():
            with np.load(path) as data:
                stage1[i] = {name: data[name] for name in data.files}
            report("cells", int(sizes[start:start + chunk].sum()))
    todo = {i: (reps[start:start + chunk],) for i, start in enumerate(starts) if i not in stage1}
    for i, part in _completed(tessellate_chunk, todo, **backend):
        stage1[i] = part
        if folder:
            atomic_write(folder / f"{tag}-cells-{i:05d}.npz", _npz_bytes(part))
        report("cells", int(sizes[i * chunk:(i + 1) * chunk].sum()))
    cells = {name: np.concatenate([stage1[i][name] for i in range(len(starts))]) if starts else np.zeros(0, np.int64)
             for name in ("tets", "closed", "open", "polys", "poly_mask", "poly_code")}

    # Stage 2: every distinct non-tetrahedral element, once.
    pairs = np.stack([cells["poly_mask"], cells["poly_code"]], axis=1)
    distinct, first, element_of = np.unique(pairs, axis=0, return_index=True, return_inverse=True)
    element_of = element_of.reshape(-1)
    owner = np.repeat(reps, cells["polys"])[first]  # a configuration holding each element
    work = [(int(mask), int(code)) for (mask, _), code in zip(distinct.tolist(), owner.tolist())]
    element_starts = range(0, len(work), ELEMENT_CHUNK)
    stage2: dict[int, tuple] = {}
    for i in range(len(element_starts)):
        path = folder / f"{tag}-elements-{i:05d}.json" if folder else None
        if path and path.exists():
            stage2[i] = tuple(json.loads(path.read_text()))
            report("elements", len(stage2[i][0]))
    todo = {i: (work[start:start + ELEMENT_CHUNK],) for i, start in enumerate(element_starts) if i not in stage2}
    for i, part in _completed(element_entries, todo, **backend):
        stage2[i] = part
        if folder:
            atomic_write(folder / f"{tag}-elements-{i:05d}.json", json.dumps(part, sort_keys=True))
        report("elements", len(part[0]))
    tetrahedron, types = _tetrahedron()
    entries = tetrahedron + [entry for i in range(len(element_starts)) for entry in stage2[i][0]]
    for i in range(len(element_starts)):
        types.update(stage2[i][1])
    summary = statistics(sizes, cells, element_of + 1, entries, types)
    return {
        "study": "intersection", "box": ["1", "1", "1"], "face_points": "octree",
        "resolution": resolution, "insertion_order": order,
        "configurations": configurations, "orbits": len(reps),
        **summary,
    }


def _npz_bytes(arrays: dict) -> bytes:
    import io

    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    return buffer.getvalue()


def statistics(sizes: np.ndarray, cells: dict, element_of: np.ndarray, entries: list, types: dict) -> dict:
    """FVM counts and, per criterion, the kept types, totals, frequencies and splits.

    ``entries[e]`` is ``[type id, options per split criterion]`` of element e
    (entry 0 the tetrahedron); ``element_of`` gives each non-tetrahedral cell's
    entry, in the order of ``cells``.
    """
    from ..catalogue import minimal_kept_sets

    sizes = np.asarray(sizes, dtype=np.int64)
    n = len(sizes)
    # One row per (configuration, element), tetrahedra as one row with their count.
    config = np.concatenate([np.arange(n), np.repeat(np.arange(n), cells["polys"])])
    element = np.concatenate([np.zeros(n, dtype=np.int64), element_of])
    multiplicity = np.concatenate([cells["tets"], np.ones(len(element_of), dtype=np.int64)])
    keep = multiplicity > 0
    config, element, multiplicity = config[keep], element[keep], multiplicity[keep]
    weight = np.bincount(element, weights=sizes[config] * multiplicity, minlength=len(entries)).astype(np.int64)

    criteria = {}
    for index, criterion in enumerate(("optimal", *SPLIT_CRITERIA)):
        if criterion == "optimal":
            pieces = [(entry[0],) for entry in entries]
            splits: dict = {}
        else:
            used = [e for e in range(len(entries)) if weight[e] > 0]
            instances = [{frozenset(option) for option in map(tuple, entries[e][index])} for e in used]
            _, candidates = minimal_kept_sets(instances)
            best = None
            for kept in candidates:
                chosen = [next((tuple(o) for o in entry[index] if set(o) <= kept), None) for entry in entries]
                total = sum(int(weight[e]) * len(chosen[e]) for e in used)
                key = (total, sorted(kept))
                if best is None or key < best[0]:
                    best = (key, chosen)
            kept, pieces = best[0][1], best[1]
            splits = {}
            for e in used:
                if pieces[e] != (entries[e][0],):
                    splits.setdefault(entries[e][0], {}).setdefault(pieces[e], 0)
                    splits[entries[e][0]][pieces[e]] += int(weight[e])
        criteria[criterion] = _frequencies(pieces, weight, sizes, config, element, types, splits)
        if criterion != "optimal":
            criteria[criterion]["kept"] = kept
    return {
        "fvm_adequate": int(sizes[cells["closed"]].sum()),
        "fvm_adequate_open": int(sizes[cells["open"]].sum()),
        "criteria": criteria,
    }


def _frequencies(pieces, weight, sizes, config, element, types, splits) -> dict:
    type_ids = sorted({t for e in range(len(pieces)) if weight[e] > 0 for t in pieces[e]})
    index = {t: i for i, t in enumerate(type_ids)}
    counts = np.zeros(len(type_ids), dtype=np.int64)
    for e, element_pieces in enumerate(pieces):
        if weight[e] > 0:
            for t in element_pieces:
                counts[index[t]] += weight[e]
    # Configurations holding a type: distinct (configuration, type) pairs, weighted by orbit size.
    distinct_types = [sorted({index[t] for t in p}) if p else [] for p in pieces]
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
    total = int(counts.sum())
    rows_out = {}
    for i in sorted(range(len(type_ids)), key=lambda i: (-counts[i], type_ids[i])):
        name, v, e, f, cls = types[type_ids[i]]
        rows_out[type_ids[i]] = {"name": name, "paper_class": cls, "count": int(counts[i]),
                                 "share": round(int(counts[i]) / total, 6),
                                 "configurations": int(configurations[i]), "vertices": v, "edges": e, "faces": f}
    data = {"total": total, "types_count": len(rows_out),
            "paper_classes_count": len({r["paper_class"] or k for k, r in rows_out.items()}), "types": rows_out}
    if splits:
        data["splits"] = {type_id: [{"pieces": list(p), "configurations": n} for p, n in sorted(used.items())]
                          for type_id, used in sorted(splits.items())}
    return data
