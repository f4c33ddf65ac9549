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

from .configuration import edge_axis

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
# Running the study: one tessellation per orbit representative, in chunks that
# worker processes take, each chunk's statistics checkpointed so that an
# interrupted run resumes where it stopped.

CHUNK = 2000


def orbits(resolution: int = 16, order: str = "edge") -> tuple[np.ndarray, np.ndarray, int]:
    """Orbit representatives (codes as base-16 numbers, sorted) with their sizes, and the configuration count.

    The family is not closed under the cube's symmetries (a reflected configuration
    has positions 1 - t, which the midpoint scheme does not produce), so an orbit
    here collects only the family's members that map onto each other.
    """
    from .configuration import Box
    from .symmetry import box_symmetries, orbit_keys

    digits = intersection_codes(resolution, order)
    keys, _ = orbit_keys(digits, box_symmetries(Box.parse(["1", "1", "1"])))
    reps, sizes = np.unique(keys, return_counts=True)
    return reps, sizes, len(digits)


def chunk_statistics(reps: list[int], sizes: list[int]) -> dict:
    """Statistics of a chunk of orbit representatives, each counted with its orbit size."""
    from .configuration import Configuration
    from .paper import paper_class
    from .symmetry import key_code
    from .tessellation import tessellate

    counts: dict[str, int] = {}
    configurations: dict[str, int] = {}
    types: dict[str, list] = {}
    closed = open_ = total = 0
    for key, size in zip(reps, sizes):
        tess = tessellate(Configuration.from_code(key_code(key)))
        closed += size * tess.fvm_adequate
        open_ += size * tess.fvm_adequate_open
        total += size * len(tess.elements)
        seen = set()
        for element in tess.elements:
            t = element.type
            counts[t.id] = counts.get(t.id, 0) + size
            types[t.id] = [t.name, t.vertices, t.edges, t.faces, (paper_class(t) or {}).get("name")]
            seen.add(t.id)
        for type_id in seen:
            configurations[type_id] = configurations.get(type_id, 0) + size
    return {"orbits": len(reps), "fvm_adequate": closed, "fvm_adequate_open": open_, "total": total,
            "counts": counts, "configurations": configurations, "types": types}


def _merge(parts) -> dict:
    merged = {"orbits": 0, "fvm_adequate": 0, "fvm_adequate_open": 0, "total": 0,
              "counts": {}, "configurations": {}, "types": {}}
    for part in parts:
        for key in ("orbits", "fvm_adequate", "fvm_adequate_open", "total"):
            merged[key] += part[key]
        for key in ("counts", "configurations"):
            for type_id, n in part[key].items():
                merged[key][type_id] = merged[key].get(type_id, 0) + n
        merged["types"].update(part["types"])
    return merged


def run_intersection(resolution: int = 16, order: str = "edge", jobs: int = 1, checkpoints=None,
                     progress=None, chunk: int = CHUNK) -> dict:
    """The intersection study's summary (optimal criterion), in the shape of the bisection study's.

    ``checkpoints``: a folder keeping each finished chunk's statistics; chunks found
    there are not computed again, so an interrupted run resumes.
    """
    import json
    from concurrent.futures import ProcessPoolExecutor
    from pathlib import Path

    from .yamlio import atomic_write

    reps, sizes, configurations = orbits(resolution, order)
    chunks = [(reps[i:i + chunk].tolist(), sizes[i:i + chunk].tolist()) for i in range(0, len(reps), chunk)]
    folder = Path(checkpoints) if checkpoints else None
    tag = f"r{resolution}-{order}-c{chunk}"
    parts: dict[int, dict] = {}
    if folder:
        folder.mkdir(parents=True, exist_ok=True)
        for i in range(len(chunks)):
            path = folder / f"{tag}-chunk{i:05d}.json"
            if path.exists():
                parts[i] = json.loads(path.read_text())
                if progress:
                    progress(sum(chunks[i][1]))
    todo = [i for i in range(len(chunks)) if i not in parts]

    def done(i: int, part: dict) -> None:
        parts[i] = part
        if folder:
            atomic_write(folder / f"{tag}-chunk{i:05d}.json", json.dumps(part, sort_keys=True))
        if progress:
            progress(sum(chunks[i][1]))

    if jobs <= 1:
        for i in todo:
            done(i, chunk_statistics(*chunks[i]))
    else:
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            for i, part in zip(todo, pool.map(chunk_statistics, *zip(*[chunks[i] for i in todo]))):
                done(i, part)
    merged = _merge(parts[i] for i in range(len(chunks)))
    total = merged["total"]
    type_rows = {}
    for type_id in sorted(merged["counts"], key=lambda k: (-merged["counts"][k], k)):
        name, v, e, f, cls = merged["types"][type_id]
        type_rows[type_id] = {"name": name, "paper_class": cls, "count": merged["counts"][type_id],
                              "share": round(merged["counts"][type_id] / total, 6),
                              "configurations": merged["configurations"][type_id],
                              "vertices": v, "edges": e, "faces": f}
    return {
        "study": "intersection", "box": ["1", "1", "1"], "face_points": "octree",
        "resolution": resolution, "insertion_order": order,
        "configurations": configurations, "orbits": merged["orbits"],
        "fvm_adequate": merged["fvm_adequate"], "fvm_adequate_open": merged["fvm_adequate_open"],
        "criteria": {"optimal": {"total": total, "types_count": len(type_rows),
                                 "paper_classes_count": len({r["paper_class"] or k for k, r in type_rows.items()}),
                                 "types": type_rows}},
    }
