"""Compiled kernels (numba), exact int64: the Delaunay walk, the cube at 1/16 in bulk, orbit keys.

The Delaunay walk is the one of :mod:`cospherical.core.delaunay`, compiled.

Same algorithm, same integer predicates, step for step: a first empty sphere
through the lexicographically smallest point, then from cell to cell across
faces through the pencil of spheres of each face.  Python integers never
overflow; int64 does, so the compiled walk runs only on frames whose numbers
are provably small (:func:`fits`).  Every product the walk forms is bounded by
``2**17 * W * C**8`` (C the largest coordinate, W the largest weight; the
derivation is in the comment of :func:`fits`), far below 2**63 for every box
of the paper at 1/16 positions (C = 16, W <= 4).  Larger frames take the Python
walk, which gives the same cells.

Cells come out as bit masks over frame indices (at most 62 points), faces as
index cycles counter-clockwise seen from outside, starting at their smallest
index, exactly as :func:`cospherical.core.delaunay.hull_faces` orders them.
"""

from __future__ import annotations


from typing import Sequence

import numpy as np
from numba import njit
from numpy.typing import NDArray

from ..caches import cached
from .box import CORNERS, EDGES, FACE_EDGES, FACES, edge_axis

__all__ = ["buffers", "cube_batch", "cube_tables", "fits", "orbit_keys", "walk"]

_Ints = NDArray[np.int64]  # every array of the kernels: exact int64

_MAX_POINTS = 62
_MAX_CELLS = 1024
_MAX_FACES = 8192


def fits(coords: Sequence[Sequence[int]], weights: Sequence[int], scale: int) -> bool:
    """Whether the compiled int64 walk is exact on this frame.

    With C >= |every coordinate| and L = 3 W C^2 >= every lifted coordinate:
    differences are at most 2C and 2L, a sphere's normal at most 6 (2C)^2 (2L)
    (w-column cofactors) and 6 (2C)^3, so a sphere side is at most 384 C^3 L;
    a face normal is at most 8 C^2, a face side at most 48 C^3; the pencil
    comparisons multiply the two (18432 C^6 L); the chosen neighbour sphere has
    a normal at most 5376 C^5 L and an offset at most 18432 C^6 L, so its sides
    stay below 36864 C^6 L = 110592 W C^8 < 2**17 W C^8.  The circumcenter test
    compares 5376 C^5 L with 2 W (2304 C^6) scale.
    """
    if len(coords) > _MAX_POINTS:
        return False
    c = max(1, max(abs(x) for point in coords for x in point))
    w = max(weights)
    return (1 << 17) * w * c**8 < (1 << 62) and 4608 * w * c**6 * max(scale, c) < (1 << 62)


@njit(cache=True)
def _sphere(lifted: _Ints, i: int, j: int, k: int, m: int) -> tuple[int, int, int, int, int]:
    """(a, b, c, d, offset) of the sphere through four lifted points, d > 0; d = 0 if coplanar."""
    b0, b1, b2, b3 = lifted[i, 0], lifted[i, 1], lifted[i, 2], lifted[i, 3]
    x1, y1, z1, w1 = lifted[j, 0] - b0, lifted[j, 1] - b1, lifted[j, 2] - b2, lifted[j, 3] - b3
    x2, y2, z2, w2 = lifted[k, 0] - b0, lifted[k, 1] - b1, lifted[k, 2] - b2, lifted[k, 3] - b3
    x3, y3, z3, w3 = lifted[m, 0] - b0, lifted[m, 1] - b1, lifted[m, 2] - b2, lifted[m, 3] - b3
    xy, xz, xw = x1 * y2 - x2 * y1, x1 * z2 - x2 * z1, x1 * w2 - x2 * w1
    yz, yw, zw = y1 * z2 - y2 * z1, y1 * w2 - y2 * w1, z1 * w2 - z2 * w1
    a = -(y3 * zw - z3 * yw + w3 * yz)
    b = x3 * zw - z3 * xw + w3 * xz
    c = -(x3 * yw - y3 * xw + w3 * xy)
    d = x3 * yz - y3 * xz + z3 * xy
    if d < 0:
        a, b, c, d = -a, -b, -c, -d
    return a, b, c, d, a * b0 + b * b1 + c * b2 + d * b3


@njit(cache=True)
def _side(a: int, b: int, c: int, d: int, offset: int, lifted: _Ints, p: int) -> int:
    return a * lifted[p, 0] + b * lifted[p, 1] + c * lifted[p, 2] + d * lifted[p, 3] - offset  # type: ignore[no-any-return]


@njit(cache=True)
def _contains(values: _Ints, count: int, key: int) -> bool:
    """Whether ``key`` is among ``values[:count]`` (a few dozen: a scan beats a hash set)."""
    for g in range(count):
        if values[g] == key:
            return True
    return False


@njit(cache=True)
def _hull(coords: _Ints, members: _Ints, count: int, face_nodes: _Ints, face_len: _Ints, face_normal: _Ints,
          start: int) -> int:
    """Append the hull faces of ``members[:count]`` from row ``start``; the new row count, or -1."""
    found = np.zeros(64, dtype=np.int64)
    nfound = 0
    on_plane = np.empty(count, dtype=np.int64)
    row = start
    for p in range(count):
        i = members[p]
        for q in range(p + 1, count):
            j = members[q]
            for r in range(q + 1, count):
                k = members[r]
                tri = (np.int64(1) << i) | (np.int64(1) << j) | (np.int64(1) << k)
                skip = False
                for f in range(nfound):
                    if found[f] & tri == tri:
                        skip = True
                        break
                if skip:
                    continue
                ux, uy, uz = coords[j, 0] - coords[i, 0], coords[j, 1] - coords[i, 1], coords[j, 2] - coords[i, 2]
                vx, vy, vz = coords[k, 0] - coords[i, 0], coords[k, 1] - coords[i, 1], coords[k, 2] - coords[i, 2]
                nx, ny, nz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
                if nx == 0 and ny == 0 and nz == 0:
                    continue
                offset = nx * coords[i, 0] + ny * coords[i, 1] + nz * coords[i, 2]
                above = False
                below = False
                n_on = 0
                mask = np.int64(0)
                for s in range(count):
                    m = members[s]
                    side = nx * coords[m, 0] + ny * coords[m, 1] + nz * coords[m, 2] - offset
                    if side > 0:
                        above = True
                    elif side < 0:
                        below = True
                    else:
                        on_plane[n_on] = m
                        n_on += 1
                        mask |= np.int64(1) << m
                    if above and below:
                        break
                if above and below:
                    continue
                if not (above or below) or row >= face_nodes.shape[0] or nfound >= 64:
                    return -1
                if above:
                    nx, ny, nz = -nx, -ny, -nz
                found[nfound] = mask
                nfound += 1
                if n_on == 3:
                    same = (uy * vz - uz * vy) * nx + (uz * vx - ux * vz) * ny + (ux * vy - uy * vx) * nz
                    if same < 0:
                        on_plane[1], on_plane[2] = on_plane[2], on_plane[1]
                else:
                    # Counter-clockwise seen from the normal's tip, around the smallest index:
                    # y comes after x when normal . ((x - o) x (y - o)) > 0.
                    o = on_plane[0]
                    for t in range(2, n_on):
                        y = on_plane[t]
                        pos = t
                        while pos > 1:
                            x = on_plane[pos - 1]
                            ax, ay, az = coords[x, 0] - coords[o, 0], coords[x, 1] - coords[o, 1], coords[x, 2] - coords[o, 2]
                            bx, by, bz = coords[y, 0] - coords[o, 0], coords[y, 1] - coords[o, 1], coords[y, 2] - coords[o, 2]
                            turn = nx * (ay * bz - az * by) + ny * (az * bx - ax * bz) + nz * (ax * by - ay * bx)
                            if turn > 0:
                                break
                            on_plane[pos] = x
                            pos -= 1
                        on_plane[pos] = y
                for t in range(n_on):
                    face_nodes[row, t] = on_plane[t]
                face_len[row] = n_on
                face_normal[row, 0], face_normal[row, 1], face_normal[row, 2] = nx, ny, nz
                row += 1
    return row


@njit(cache=True)
def walk(coords: _Ints, lifted: _Ints, weights: _Ints, cell_mask: _Ints, cell_sphere: _Ints, face_cell: _Ints,
         face_nodes: _Ints, face_len: _Ints, face_normal: _Ints) -> tuple[int, int]:
    """The Delaunay cells of the frame ``coords`` / ``lifted``, into the output arrays.

    Returns ``(cells, faces)``, or ``(-1, -1)`` when an output array is too small
    or the points do not span 3D (the caller then takes the Python walk).
    """
    n = coords.shape[0]
    # The indices and counts handed to the helpers start as np.int64, never as a literal 0: numba would
    # compile each helper a second time for the literal's own type (a second of compiling in a fresh clone).
    # First cell: an empty sphere through the lexicographically smallest point.
    anchor = np.int64(0)
    for p in range(1, n):
        for axis in range(3):
            if coords[p, axis] != coords[anchor, axis]:
                if coords[p, axis] < coords[anchor, axis]:
                    anchor = p
                break
    keys = np.empty(n - 1, dtype=np.int64)
    others = np.empty(n - 1, dtype=np.int64)
    t = 0
    for p in range(n):
        if p != anchor:
            dist = 0
            for axis in range(3):
                diff = coords[p, axis] - coords[anchor, axis]
                dist += weights[axis] * diff * diff
            keys[t] = dist * 64 + p
            others[t] = p
            t += 1
    # Nearest first (keys are distinct: the index is in the low bits).  Insertion sort on at most 61
    # keys: np.argsort would compile numba's quicksort into the walk, about a second of compiling.
    for t in range(1, n - 1):
        key, other = keys[t], others[t]
        pos = t
        while pos > 0 and keys[pos - 1] > key:
            keys[pos], others[pos] = keys[pos - 1], others[pos - 1]
            pos -= 1
        keys[pos], others[pos] = key, other
    ncells = np.int64(0)
    members = np.empty(n, dtype=np.int64)
    found = False
    for q in range(n - 1):
        for r in range(q + 1, n - 1):
            for s in range(r + 1, n - 1):
                a, b, c, d, off = _sphere(lifted, anchor, others[q], others[r], others[s])
                if d == 0:
                    continue
                mask = np.int64(0)
                empty = True
                for p in range(n):
                    side = _side(a, b, c, d, off, lifted, p)
                    if side < 0:
                        empty = False
                        break
                    if side == 0:
                        mask |= np.int64(1) << p
                if empty:
                    cell_mask[0] = mask
                    cell_sphere[0, 0], cell_sphere[0, 1], cell_sphere[0, 2] = a, b, c
                    cell_sphere[0, 3], cell_sphere[0, 4] = d, off
                    ncells = 1
                    found = True
                    break
            if found:
                break
        if found:
            break
    if not found:
        return -1, -1
    crossed = np.empty(face_nodes.shape[0], dtype=np.int64)
    ncrossed = np.int64(0)
    beyond = np.empty(n, dtype=np.int64)
    nfaces = np.int64(0)
    done = 0
    while done < ncells:
        mask = cell_mask[done]
        count = np.int64(0)
        for p in range(n):
            if mask >> p & 1:
                members[count] = p
                count += 1
        first_face = nfaces
        nfaces = _hull(coords, members, count, face_nodes, face_len, face_normal, nfaces)
        if nfaces < 0:
            return -1, -1
        for f in range(first_face, nfaces):
            face_cell[f] = done
        done += 1
        for f in range(first_face, nfaces):
            key = np.int64(0)
            for t in range(face_len[f]):
                key |= np.int64(1) << face_nodes[f, t]
            if _contains(crossed, ncrossed, key):
                continue
            crossed[ncrossed] = key
            ncrossed += 1
            nx, ny, nz = face_normal[f, 0], face_normal[f, 1], face_normal[f, 2]
            i, j, k = face_nodes[f, 0], face_nodes[f, 1], face_nodes[f, 2]
            offset = nx * coords[i, 0] + ny * coords[i, 1] + nz * coords[i, 2]
            nb = 0
            for p in range(n):
                if nx * coords[p, 0] + ny * coords[p, 1] + nz * coords[p, 2] > offset:
                    beyond[nb] = p
                    nb += 1
            if nb == 0:
                continue
            # The pencil of spheres through the face's circle: sphere(lam) = first + lam * plane;
            # the neighbour's sphere has the largest lam_y = -first(y) / plane(y) beyond the face.
            a, b, c, d, off = _sphere(lifted, i, j, k, beyond[0])
            best_h = np.int64(0)
            best_g = np.int64(1)
            for t in range(1, nb):
                y = beyond[t]
                h = _side(a, b, c, d, off, lifted, y)
                g = nx * coords[y, 0] + ny * coords[y, 1] + nz * coords[y, 2] - offset
                if -h * best_g > -best_h * g:
                    best_h, best_g = h, g
            sa = best_g * a - best_h * nx
            sb = best_g * b - best_h * ny
            sc = best_g * c - best_h * nz
            sd = best_g * d
            so = best_g * off - best_h * offset
            neighbour = np.int64(0)
            for p in range(n):
                if _side(sa, sb, sc, sd, so, lifted, p) == 0:
                    neighbour |= np.int64(1) << p
            if _contains(cell_mask, ncells, neighbour):
                continue
            if ncells >= cell_mask.shape[0]:
                return -1, -1
            cell_mask[ncells] = neighbour
            cell_sphere[ncells, 0], cell_sphere[ncells, 1], cell_sphere[ncells, 2] = sa, sb, sc
            cell_sphere[ncells, 3], cell_sphere[ncells, 4] = sd, so
            ncells += 1
    return ncells, nfaces


def buffers(points: int) -> tuple[_Ints, _Ints, _Ints, _Ints, _Ints, _Ints]:
    """Output arrays for :func:`walk` on up to ``points`` points."""
    return (
        np.empty(_MAX_CELLS, dtype=np.int64),
        np.empty((_MAX_CELLS, 5), dtype=np.int64),
        np.empty(_MAX_FACES, dtype=np.int64),
        np.empty((_MAX_FACES, points), dtype=np.int64),
        np.empty(_MAX_FACES, dtype=np.int64),
        np.empty((_MAX_FACES, 3), dtype=np.int64),
    )


# ---------------------------------------------------------------------------
# Many configurations of the cube at 1/16 positions in one call (the
# intersection study): points built from the code digits, the walk, and per
# cell what the statistics need.


@cached(maxsize=1)  # built once per process, shared by every chunk
def cube_tables() -> tuple[_Ints, _Ints, _Ints, _Ints, _Ints]:
    """Point tables of the cube in 16ths: corner coordinates, edge start corners and axes, faces' edge pairs."""
    corners = np.array(CORNERS, dtype=np.int64) * 16
    starts = np.array([min((CORNERS[i] for i in EDGES[k])) for k in range(12)], dtype=np.int64) * 16
    axes = np.array([edge_axis(k) for k in range(12)], dtype=np.int64)
    # Per face: its four edges with the two of one axis first, and its first corner.
    face_edges = np.array([sorted(FACE_EDGES[f], key=lambda k: (edge_axis(k), k)) for f in range(6)], dtype=np.int64)
    face_base = corners[[FACES[f][0] for f in range(6)]]
    return corners, starts, axes, face_edges, face_base


@njit(cache=True)
def _cube_points(digits: _Ints, corners: _Ints, starts: _Ints, axes: _Ints, face_edges: _Ints, face_base: _Ints,
                 ids: _Ints, coords: _Ints, lifted: _Ints) -> int:
    """The octree point set of one configuration (digits in 16ths); returns the point count."""
    n = 0
    for c in range(8):
        ids[n] = c
        coords[n, 0], coords[n, 1], coords[n, 2] = corners[c, 0], corners[c, 1], corners[c, 2]
        n += 1
    for k in range(12):
        if digits[k] != 0:
            ids[n] = 8 + k
            coords[n, 0], coords[n, 1], coords[n, 2] = starts[k, 0], starts[k, 1], starts[k, 2]
            coords[n, axes[k]] = digits[k]
            n += 1
    faces = 0
    for f in range(6):
        e0, e1, e2, e3 = face_edges[f, 0], face_edges[f, 1], face_edges[f, 2], face_edges[f, 3]
        if digits[e0] != 0 and digits[e0] == digits[e1] and digits[e2] != 0 and digits[e2] == digits[e3]:
            ids[n] = 20 + f
            coords[n, 0], coords[n, 1], coords[n, 2] = face_base[f, 0], face_base[f, 1], face_base[f, 2]
            coords[n, axes[e0]] = digits[e0]
            coords[n, axes[e2]] = digits[e2]
            n += 1
            faces += 1
    if faces == 6:
        ids[n] = 26
        for k in range(12):
            coords[n, axes[k]] = digits[k]
        n += 1
    for p in range(n):
        lifted[p, 0], lifted[p, 1], lifted[p, 2] = coords[p, 0], coords[p, 1], coords[p, 2]
        lifted[p, 3] = coords[p, 0] ** 2 + coords[p, 1] ** 2 + coords[p, 2] ** 2
    return n


@njit(cache=True)
def cube_batch(codes: _Ints, corners: _Ints, starts: _Ints, axes: _Ints, face_edges: _Ints, face_base: _Ints,
               tets: _Ints, closed: NDArray[np.bool_], open_: NDArray[np.bool_], polys: _Ints, poly_mask: _Ints,
               poly_code: _Ints, every_cell: bool = False) -> int:
    """Tessellate the cube configurations ``codes`` (base-16 numbers, 1/16 positions, octree points).

    Per configuration: ``tets`` the number of tetrahedra, ``closed``/``open_``
    whether every circumcenter lies in the closed/open box, ``polys`` the number
    of other cells (of all cells with ``every_cell``, for pattern tables); each
    such cell is written, in the walk's order, as its node-id bit mask and the
    code masked to the digits its points depend on (equal pairs mean equal
    geometry: same nodes at the same places).  Returns the number of cells
    written, or -1 - i when configuration i needs the Python walk.
    """
    ids = np.empty(27, dtype=np.int64)
    coords = np.zeros((27, 3), dtype=np.int64)
    lifted = np.empty((27, 4), dtype=np.int64)
    weights = np.ones(3, dtype=np.int64)
    cell_mask = np.empty(_MAX_CELLS, dtype=np.int64)
    cell_sphere = np.empty((_MAX_CELLS, 5), dtype=np.int64)
    face_cell = np.empty(_MAX_FACES, dtype=np.int64)
    face_nodes = np.empty((_MAX_FACES, 27), dtype=np.int64)
    face_len = np.empty(_MAX_FACES, dtype=np.int64)
    face_normal = np.empty((_MAX_FACES, 3), dtype=np.int64)
    digits = np.empty(12, dtype=np.int64)
    face_digits = np.zeros(6, dtype=np.int64)
    for f in range(6):
        for t in range(4):
            face_digits[f] |= np.int64(1) << face_edges[f, t]
    written = 0
    for i in range(codes.shape[0]):
        for k in range(12):
            digits[k] = codes[i] >> (4 * (11 - k)) & 15
        n = _cube_points(digits, corners, starts, axes, face_edges, face_base, ids, coords, lifted)
        ncells, _ = walk(coords[:n], lifted[:n], weights, cell_mask, cell_sphere, face_cell, face_nodes,
                         face_len, face_normal)
        if ncells < 0:
            return -1 - i
        tets[i] = 0
        polys[i] = 0
        closed[i] = True
        open_[i] = True
        for c in range(ncells):
            mask = cell_mask[c]
            d = cell_sphere[c, 3]
            # circumcenter (unit) = -normal[axis] / (2 d 16): in [0, 1] iff 0 <= -normal[axis] <= 32 d.
            for axis in range(3):
                x = -cell_sphere[c, axis]
                if x < 0 or x > 32 * d:
                    closed[i] = False
                if x <= 0 or x >= 32 * d:
                    open_[i] = False
            count = 0
            node_mask = np.int64(0)
            relevant = np.int64(0)
            for p in range(n):
                if mask >> p & 1:
                    count += 1
                    node = ids[p]
                    node_mask |= np.int64(1) << node
                    if node == 26:
                        relevant = np.int64(4095)
                    elif node >= 20:
                        relevant |= face_digits[node - 20]
                    elif node >= 8:
                        relevant |= np.int64(1) << (node - 8)
            if count == 4:
                tets[i] += 1
                if not every_cell:
                    continue
            if written >= poly_mask.shape[0]:
                return -1 - i
            masked = np.int64(0)
            for k in range(12):
                if relevant >> k & 1:
                    masked |= digits[k] << (4 * (11 - k))
            poly_mask[written] = node_mask
            poly_code[written] = masked
            polys[i] += 1
            written += 1
    return written


@njit(cache=True)
def orbit_keys(digits: _Ints, targets: _Ints, reverse: NDArray[np.bool_], masks: _Ints, faces: _Ints
               ) -> tuple[_Ints, _Ints, _Ints]:
    """Per row of 12 digits and a point mask: the smallest image (code as base 16, then
    mask) under the symmetries, its mask, and the first symmetry reaching it.  Symmetry s
    sends edge k to ``targets[s, k]``, reversed (t -> 1 - t) where ``reverse[s, k]``, and
    face f to ``faces[s, f]``; mask bit f is face f, bit 6 the body point (fixed)."""
    n = digits.shape[0]
    best = np.empty(n, dtype=np.int64)
    best_mask = np.empty(n, dtype=np.int64)
    best_sym = np.empty(n, dtype=np.int64)
    for i in range(n):
        low = np.int64(-1)
        low_mask = np.int64(0)
        which = 0
        for s in range(targets.shape[0]):
            key = np.int64(0)
            for k in range(12):
                d = np.int64(digits[i, k])
                if reverse[s, k] and d != 0:
                    d = 16 - d
                key |= d << (4 * (11 - targets[s, k]))
            mask = masks[i] & 64
            if masks[i] != 0:  # most rows (bare codes) have no face points to map
                for f in range(6):
                    if masks[i] >> f & 1:
                        mask |= np.int64(1) << faces[s, f]
            if low < 0 or key < low or (key == low and mask < low_mask):
                low = key
                low_mask = mask
                which = s
        best[i] = low
        best_mask[i] = low_mask
        best_sym[i] = which
    return best, best_mask, best_sym
