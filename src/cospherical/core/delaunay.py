"""Delaunay cells: every cell is the convex hull of all points on one empty sphere.

The subdivision is built exactly by walking from cell to cell across interior
faces.  Across a face with points p, q, r, the neighbour's sphere belongs to the
pencil of spheres through the circle pqr; on the far side of the face those
spheres' caps are nested, so one scan for the point whose sphere contains no
other far-side point finds it.  The neighbour is then every point on that
sphere.  A face with no point beyond it lies on the convex hull.  All tests are
integer determinants (:mod:`cospherical.core.geometry`), so co-spherical points
always end up in one cell, whatever the box or Steiner positions.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from fractions import Fraction
from functools import cmp_to_key
from itertools import combinations
from typing import Sequence

from ..choices import DELAUNAY_BACKENDS, DelaunayBackend
from ..errors import InputError
from .geometry import Frame, Sphere, determinant, dot, plane_normal, sub

__all__ = ["Cell", "delaunay_cells", "hull_faces"]


@dataclass(frozen=True)
class Cell:
    """One Delaunay cell.

    ``nodes`` are node ids in increasing order; ``faces`` are node-id cycles,
    counter-clockwise seen from outside, each starting at its smallest id, in
    increasing order; ``center`` is the exact circumcenter in
    unit coordinates.
    """

    nodes: tuple[int, ...]
    faces: tuple[tuple[int, ...], ...]
    center: tuple[Fraction, Fraction, Fraction]


def hull_faces(frame: Frame, members: list[int]) -> list[tuple[tuple[int, ...], tuple[int, int, int]]]:
    """Faces of the convex hull of points in convex position (indices into the frame).

    Returns ``(cycle, outward normal)`` pairs, each cycle counter-clockwise seen
    from outside and starting at its smallest index.
    """
    coords = frame.coords
    if len(members) == 4:  # most cells: one side test per face instead of a scan of the four points
        faces = _tetrahedron_faces(coords, members)
        if faces is not None:
            return faces
    points = [(m, *coords[m]) for m in members]
    # Triples of a face with more than three points: the face is found at its first
    # triple, the others are skipped (a set lookup, not a scan of the faces found).
    done: set[tuple[int, int, int]] = set()
    faces = []
    for i, j, k in combinations(members, 3):
        if (i, j, k) in done:
            continue
        nx, ny, nz = plane_normal(coords[i], coords[j], coords[k])
        if nx == ny == nz == 0:
            continue
        x0, y0, z0 = coords[i]
        offset = nx * x0 + ny * y0 + nz * z0
        above = below = False
        on_plane = []
        for m, x, y, z in points:
            side = nx * x + ny * y + nz * z - offset
            if side > 0:
                above = True
            elif side < 0:
                below = True
            else:
                on_plane.append(m)
            if above and below:
                break
        if above and below:
            continue
        if not (above or below):
            raise ValueError("points are coplanar: no 3D hull")
        normal = (-nx, -ny, -nz) if above else (nx, ny, nz)
        if len(on_plane) > 3:
            done.update(combinations(on_plane, 3))
        faces.append((_counter_clockwise(coords, on_plane, normal) if len(on_plane) > 3 else
                      _triangle(on_plane, above), normal))
    return faces


def _tetrahedron_faces(coords: Sequence[Sequence[int]],
                       members: list[int]) -> list[tuple[tuple[int, ...], tuple[int, int, int]]] | None:
    # hull_faces of four points, the same faces in the same order: each triple of combinations() with the
    # fourth point on one side; None when the four are coplanar (hull_faces' own path says what follows).
    faces: list[tuple[tuple[int, ...], tuple[int, int, int]]] = []
    for (i, j, k), m in zip(combinations(members, 3), (members[3], members[2], members[1], members[0])):
        nx, ny, nz = plane_normal(coords[i], coords[j], coords[k])
        (x0, y0, z0), (x, y, z) = coords[i], coords[m]
        side = nx * (x - x0) + ny * (y - y0) + nz * (z - z0)
        if side == 0:
            return None
        faces.append(((i, k, j), (-nx, -ny, -nz)) if side > 0 else ((i, j, k), (nx, ny, nz)))
    return faces


def _triangle(points: list[int], above: bool) -> tuple[int, ...]:
    # points are i < j < k, and the plane normal (j - i) x (k - i) points along the outward
    # normal exactly when the other points are below it: keep the order then, else swap j and k.
    i, j, k = points
    return (i, k, j) if above else (i, j, k)


def _counter_clockwise(coords: Sequence[Sequence[int]], points: list[int], normal: Sequence[int]) -> tuple[int, ...]:
    first = min(points)
    origin = coords[first]

    def turn(x: int, y: int) -> int:
        # x before y when y lies counter-clockwise of x, seen from the normal's tip.
        return -determinant(normal, sub(coords[x], origin), sub(coords[y], origin))

    rest = sorted((p for p in points if p != first), key=cmp_to_key(turn))
    return (first, *rest)


def _first_cell(frame: Frame) -> tuple[list[int], Sphere]:
    # The lexicographically smallest point is a hull vertex, so some cell has it;
    # try spheres through it and its nearest points first.
    coords, lifted = frame.coords, frame.lifted
    anchor = min(range(len(coords)), key=lambda i: coords[i])
    (ax, ay, az), (wx, wy, wz) = coords[anchor], frame.weights
    # nearest first: the real squared distance (frame.real_dot of the difference with itself), written out
    others = sorted(
        (wx * (x - ax) ** 2 + wy * (y - ay) ** 2 + wz * (z - az) ** 2, i)
        for i, (x, y, z) in enumerate(coords) if i != anchor
    )
    for j, k, m in combinations([i for _, i in others], 3):
        sphere = frame.sphere(anchor, j, k, m)
        if sphere is None:
            continue
        sides = [sphere.side(p) for p in lifted]
        if min(sides) == 0:
            return [i for i, side in enumerate(sides) if side == 0], sphere
    raise ValueError("no empty sphere: the points do not span 3D")


def delaunay_cells(frame: Frame, backend: DelaunayBackend = "python") -> list[Cell]:
    """The Delaunay subdivision of the frame's points, cells sorted by node ids.

    ``backend``: ``"python"`` (the default) walks in Python integers;
    ``"compiled"`` takes the compiled int64 walk (:mod:`cospherical.core.compiled`)
    where its numbers provably fit, else the Python walk: both give the same
    cells on any frame.  Loading the compiled walk (numba) costs about a second
    and a half per process, while the Python walk takes about 1 ms per
    bisection configuration, so small work (one configuration, a bisection
    study: 144 orbits) keeps the default and bulk work (the intersection study)
    asks for ``"compiled"``.
    """
    if backend not in DELAUNAY_BACKENDS:
        raise InputError(f"backend {backend!r}: one of {', '.join(DELAUNAY_BACKENDS)}")
    if backend == "compiled":
        cells = _compiled_cells(frame)
        if cells is not None:
            return cells
    coords, lifted = frame.coords, frame.lifted
    # The points' extent along each axis: a face in the plane of an extreme coordinate, its normal along
    # that axis and outward, has no point beyond it (the hull's faces of a box), with no scan of the points.
    lowest = [min(p[axis] for p in coords) for axis in range(3)]
    highest = [max(p[axis] for p in coords) for axis in range(3)]
    node_id = frame.ids.__getitem__
    members, sphere = _first_cell(frame)
    seen = {frozenset(members)}
    queue = deque([(members, sphere)])
    crossed: set[frozenset[int]] = set()
    cells = []
    while queue:
        members, sphere = queue.popleft()
        faces = hull_faces(frame, members)
        cells.append(
            Cell(
                nodes=tuple(map(node_id, members)),
                faces=tuple(sorted(tuple(map(node_id, cycle)) for cycle, _ in faces)),
                center=frame.center(sphere),
            )
        )
        for cycle, normal in faces:
            key = frozenset(cycle)
            if key in crossed:
                continue
            crossed.add(key)
            nx, ny, nz = normal
            on = coords[cycle[0]]
            if ((ny == nz == 0 and on[0] == (highest[0] if nx > 0 else lowest[0]))
                    or (nx == nz == 0 and on[1] == (highest[1] if ny > 0 else lowest[1]))
                    or (nx == ny == 0 and on[2] == (highest[2] if nz > 0 else lowest[2]))):
                continue
            offset = dot(normal, on)
            beyond = [m for m, (x, y, z) in enumerate(coords) if nx * x + ny * y + nz * z > offset]
            if not beyond:
                continue
            # Spheres through the circle of i, j, k: sphere(lam) = first + lam * plane.
            # Beyond the face, y lies inside sphere(lam) exactly when lam < lam_y
            # = -first(y) / plane(y), so the neighbour's sphere has the largest lam_y.
            i, j, k = cycle[:3]
            first = frame.sphere(i, j, k, beyond[0])
            assert first is not None, "a point beyond a face's plane is off it: the four span a solid"
            best_h, best_g = 0, 1  # beyond[0] lies on `first`: lam = 0
            for y in beyond[1:]:
                h = first.side(lifted[y])
                x, y_, z, _ = lifted[y]
                g = nx * x + ny * y_ + nz * z - offset
                if -h * best_g > -best_h * g:
                    best_h, best_g = h, g
            best = first.pencil(normal, offset, best_h, best_g)
            a, b, c, d = best.normal  # best.side(point) == 0, inlined: the walk's innermost loop
            neighbour = [m for m, (x, y, z, w) in enumerate(lifted) if a * x + b * y + c * z + d * w == best.offset]
            if frozenset(neighbour) not in seen:
                seen.add(frozenset(neighbour))
                queue.append((neighbour, best))
    cells.sort(key=lambda cell: cell.nodes)
    return cells


def _compiled_cells(frame: Frame) -> list[Cell] | None:
    import numpy as np

    from . import compiled

    if not compiled.fits(frame.coords, frame.weights, frame.scale):
        return None
    out = compiled.buffers(len(frame.coords))
    ncells, nfaces = compiled.walk(
        np.array(frame.coords, dtype=np.int64), np.array(frame.lifted, dtype=np.int64),
        np.array(frame.weights, dtype=np.int64), *out)
    if ncells < 0:
        return None
    masks, spheres = out[0][:ncells].tolist(), out[1][:ncells].tolist()
    face_cell, face_nodes, face_len = (a[:nfaces].tolist() for a in out[2:5])
    ids = frame.ids
    faces: list[list[tuple[int, ...]]] = [[] for _ in range(ncells)]
    for f in range(nfaces):
        faces[face_cell[f]].append(tuple(ids[i] for i in face_nodes[f][:face_len[f]]))
    cells = []
    for c in range(ncells):
        a, b, cc, d, offset = spheres[c]
        cells.append(Cell(
            nodes=tuple(ids[i] for i in range(len(ids)) if masks[c] >> i & 1),
            faces=tuple(sorted(faces[c])),
            center=frame.center(Sphere((a, b, cc, d), offset)),
        ))
    cells.sort(key=lambda cell: cell.nodes)
    return cells
