"""The dual's surfaces: each vertex's part of flat faces (the domain's boundary, a device's interfaces), exactly.

The box method gives a vertex the part of a boundary face nearest to it: the triangles
between the vertex, the midpoints of its two edges of the face and the face's circle
centre (a face of a co-spherical element is co-circular).  These are the pieces
:func:`~cospherical.mesh.dual.element_pieces` gives a face in a coordinate plane, signed
the same way (a circle centre beyond an edge gives a negative triangle), so on a box
they sum to the boundary areas the dual computes element by element.  A device's domain
is a union of boxes: its boundary is the faces met by one element only, wherever they
lie, and an interface the faces between elements of two regions; both are sets of faces,
and this module measures any such set.

Exact: the faces' vertices are grid points, so a part is a rational number of squared
grid steps, computed once per face shape (up to translation and scaling by powers of
two: parts scale with the square of the size) and summed in integers.

Examples
--------
>>> square = np.array([[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0]])
>>> axes, numerators, denominator = face_parts(square, np.array([[0, 1, 2, 3]]), (1, 1, 1))
>>> axes.tolist(), (numerators / denominator).tolist()
([2], [[1.0, 1.0, 1.0, 1.0]])
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Sequence

import numpy as np

from ..errors import InputError
from .dual import Dual, InterfaceParts, boundary_areas

__all__ = ["boundary_parts", "edge_keys", "face_parts", "interface_parts", "polygon_parts", "set_domain_boundary",
           "vertex_parts"]


def polygon_parts(points: list[tuple[Fraction, Fraction]], weights: tuple[Fraction, Fraction] = (Fraction(1), Fraction(1))
                  ) -> list[Fraction]:
    """Each vertex's part of a co-circular polygon's area (circle centre, edge midpoints), exactly.

    ``points`` in coordinates whose unit steps have squared lengths ``weights`` (a grid
    of a box that is not a cube): the circle is a circle of the real plane, the parts are
    in the coordinates' units of area.  Positive for a polygon around its centre whatever
    its orientation; they sum to its area.

    >>> polygon_parts([(Fraction(0), Fraction(0)), (Fraction(2), Fraction(0)), (Fraction(0), Fraction(2))])
    [Fraction(1, 1), Fraction(1, 2), Fraction(1, 2)]
    """
    (x0, y0), (x1, y1), (x2, y2) = points[:3]
    # the circle's centre: equidistant from the first three points in the real plane's metric
    wx, wy = weights
    a1, b1, c1 = 2 * wx * (x1 - x0), 2 * wy * (y1 - y0), wx * (x1 * x1 - x0 * x0) + wy * (y1 * y1 - y0 * y0)
    a2, b2, c2 = 2 * wx * (x2 - x0), 2 * wy * (y2 - y0), wx * (x2 * x2 - x0 * x0) + wy * (y2 * y2 - y0 * y0)
    det = a1 * b2 - a2 * b1
    fx, fy = Fraction(c1 * b2 - c2 * b1) / det, Fraction(a1 * c2 - a2 * c1) / det
    n = len(points)
    twice = sum(points[i][0] * points[(i + 1) % n][1] - points[(i + 1) % n][0] * points[i][1] for i in range(n))
    sign = 1 if twice > 0 else -1
    parts = [Fraction(0)] * n
    for i in range(n):
        (ux, uy), (vx, vy) = points[i], points[(i + 1) % n]
        half = sign * ((vx - ux) * (fy - uy) - (vy - uy) * (fx - ux)) / 4  # half the triangle (u, v, centre)
        parts[i] += half
        parts[(i + 1) % n] += half
    return parts


def face_parts(vertices: np.ndarray, faces: np.ndarray, squared: Sequence[Fraction]
               ) -> tuple[np.ndarray, np.ndarray, int]:
    """Each face's axis and each of its corners' part of its area, exactly, in squared grid steps.

    ``vertices``: grid points (n x 3) of a box whose sides have the squared lengths
    ``squared`` (the circles are the real ones: a grid step is longer along one axis than
    another); ``faces``: polygons of vertex ids (F x w, -1 padded), each flat in a
    coordinate plane and co-circular.  Returns the axis normal
    to each face (F,), the parts' numerators (F x w, 0 in the padding; int64, or Python
    integers when int64 could overflow in sums) and their common denominator.  A face
    that is not flat in a coordinate plane, or whose first three corners are on a line,
    raises :class:`~cospherical.errors.InputError`.
    """
    faces = np.asarray(faces, dtype=np.int64)
    count, width = faces.shape
    if not count:
        return np.zeros(0, dtype=np.int64), np.zeros((0, width), dtype=np.int64), 1
    used = faces >= 0
    points = np.asarray(vertices, dtype=np.int64)[np.maximum(faces, 0)]
    flat = np.stack([np.all(~used | (points[:, :, k] == points[:, :1, k]), axis=1) for k in range(3)], axis=1)
    if not np.all(flat.sum(axis=1) == 1):
        raise InputError(f"face {int(np.flatnonzero(flat.sum(axis=1) != 1)[0])} is not flat in a coordinate plane")
    axes = np.argmax(flat, axis=1)
    plane = np.stack([np.take_along_axis(points, ((axes + k) % 3)[:, None, None], axis=2)[:, :, 0]
                      for k in (1, 2)], axis=2)  # the two in-plane coordinates, F x w x 2
    relative = np.where(used[..., None], plane - plane[:, :1], 0)
    spread = np.gcd.reduce(np.abs(relative).reshape(count, -1), axis=1)
    scale = np.where(spread > 0, spread & -spread, 1)  # the largest power of two dividing every offset
    shapes = np.concatenate([axes[:, None], used.sum(axis=1)[:, None],
                             np.where(used[..., None], relative // scale[:, None, None], 0).reshape(count, -1)], axis=1)
    rows = np.ascontiguousarray(shapes).view(np.dtype((np.void, shapes.shape[1] * 8))).ravel()
    distinct, first, inverse = np.unique(rows, return_index=True, return_inverse=True)
    weights = [Fraction(w) for w in squared]
    parts = []
    for f in first.tolist():
        size = int(used[f].sum())
        corners = [(Fraction(int(x)), Fraction(int(y))) for x, y in (relative[f, :size] // int(scale[f])).tolist()]
        try:
            axis = int(axes[f])
            parts.append(polygon_parts(corners, (weights[(axis + 1) % 3], weights[(axis + 2) % 3])))
        except ZeroDivisionError:
            raise InputError(f"face {f}: its first three corners are on one line") from None
    denominator = math.lcm(1, *(q.denominator for shape in parts for q in shape))
    table = [[int(q * denominator) for q in shape] + [0] * (width - len(shape)) for shape in parts]
    largest = max((abs(v) for row in table for v in row), default=0) * int(scale.max()) ** 2
    kind = np.int64 if largest * max(count, 1) * width < 2**62 else object
    numerators = np.array(table, dtype=kind)[inverse.reshape(-1)] * (scale.astype(kind) ** 2)[:, None]
    return axes, numerators, denominator


def vertex_parts(vertices: np.ndarray, faces: np.ndarray, which: np.ndarray, sets: int, grid: int,
                 lengths: tuple[Fraction, Fraction, Fraction]) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Per (vertex, set) pair, sorted, the vertex's part of the set's faces' area, exactly, in device units.

    ``which``: each face's set (its interface, its contact); ``grid`` intervals per side of
    the bounding box of rational ``lengths``.  Returns the rows' vertices and sets, their
    numerators (int64, or Python integers) and the common denominator.
    """
    faces = np.asarray(faces, dtype=np.int64)
    squared = [Fraction(x) ** 2 for x in lengths]
    axes, numerators, denominator = face_parts(vertices, faces, squared)
    # a squared grid step in the plane normal to k is lengths[k+1] * lengths[k+2] / grid**2: one integer factor per axis
    steps = [Fraction(lengths[(k + 1) % 3]) * Fraction(lengths[(k + 2) % 3]) / grid ** 2 for k in range(3)]
    common = math.lcm(*(denominator * f.denominator for f in steps))
    factors = [f.numerator * (common // (denominator * f.denominator)) for f in steps]
    kind = object if numerators.dtype == object or \
        int(np.abs(numerators).max(initial=0)) * max(factors) * max(faces.size, 1) >= 2**62 else np.int64
    scaled = numerators.astype(kind) * np.array(factors, dtype=kind)[axes][:, None]
    used = faces >= 0
    keys = (faces * max(sets, 1) + np.asarray(which, dtype=np.int64)[:, None])[used]
    pairs, inverse = np.unique(keys, return_inverse=True)
    sums = np.zeros(len(pairs), dtype=kind)
    np.add.at(sums, inverse.reshape(-1), scaled[used])
    # the smallest denominator of all the parts: what the numerators over ``common`` have in common divides out
    reduced = common // math.gcd(common, *(int(x) for x in np.unique(sums).tolist()))
    if reduced != common:
        sums = sums // (common // reduced)
    return pairs // max(sets, 1), pairs % max(sets, 1), sums, reduced


def boundary_parts(vertices: np.ndarray, faces: np.ndarray, squared: Sequence[Fraction]
                   ) -> tuple[np.ndarray, np.ndarray, int]:
    """The domain's boundary faces measured per vertex: which vertices they hold, and each vertex's part of them
    per axis (n x 3: the faces normal to x, y, z) in squared grid steps, over a common denominator (a box of
    squared side lengths ``squared``)."""
    faces = np.asarray(faces, dtype=np.int64)
    axes, numerators, denominator = face_parts(vertices, faces, squared)
    used = faces >= 0
    exact = np.zeros((len(vertices), 3), dtype=numerators.dtype)
    np.add.at(exact, (faces[used], np.broadcast_to(axes[:, None], faces.shape)[used]), numerators[used])
    on = np.zeros(len(vertices), dtype=bool)
    on[faces[used]] = True
    return on, exact, denominator


def edge_keys(faces: np.ndarray, count: int) -> np.ndarray:
    """The distinct edges of polygons (rows of vertex ids, -1 padded) as keys ``i * count + j``, ``i < j``."""
    faces = np.asarray(faces, dtype=np.int64)
    following = np.roll(faces, -1, axis=1)
    following = np.where(following >= 0, following, faces[:, :1])  # the last corner closes on the first
    keys = np.minimum(faces, following) * count + np.maximum(faces, following)
    return np.unique(keys[faces >= 0])


def set_domain_boundary(dual: Dual, faces: np.ndarray, edges: np.ndarray | None = None) -> None:
    """Make ``dual``'s boundary figures the true boundary's: ``faces`` (every face met by one element only).

    Sets ``boundary`` (the vertices of those faces), the boundary areas (exact per axis, as
    :class:`~cospherical.mesh.dual.Dual` holds them) and ``boundary_edge``.  On a box these
    are the figures the dual computes element by element, exactly.  ``edges``: the faces'
    :func:`edge_keys`, when the caller has them.
    """
    on, exact, denominator = boundary_parts(dual.grid_vertices, faces, [Fraction(x) for x in dual.box.squared])
    dual.boundary = on
    dual.boundary_area_exact = exact
    dual.boundary_area_denominator = denominator * dual.grid ** 2  # squared grid steps over a side's
    dual.boundary_area = boundary_areas(exact, dual.boundary_area_denominator, dual.boundary_factors_squared)
    count = len(dual.grid_vertices)
    keys = dual.edges[:, 0].astype(np.int64) * count + dual.edges[:, 1]  # increasing: the edges are sorted
    # the few boundary edges looked up among all the edges (np.isin would sort them all)
    boundary = edge_keys(faces, count) if edges is None else edges
    at = np.minimum(np.searchsorted(keys, boundary), max(len(keys) - 1, 0))
    dual.boundary_edge = np.zeros(len(keys), dtype=bool)
    if len(keys):
        dual.boundary_edge[at[keys[at] == boundary]] = True


def interface_parts(vertices: np.ndarray, grid: int, lengths: tuple[Fraction, Fraction, Fraction],
                    names: tuple[str, ...], regions: np.ndarray, faces: np.ndarray, which: np.ndarray
                    ) -> InterfaceParts:
    """A device's interfaces measured (see :class:`~cospherical.mesh.dual.InterfaceParts`): ``regions`` the
    region pairs, ``faces`` the interface polygons and ``which`` each one's interface; ``names`` the regions'."""
    regions = np.asarray(regions, dtype=np.int32).reshape(-1, 2)
    faces = np.asarray(faces)
    if not len(faces):
        faces = np.full((0, 4), -1, dtype=np.int32)
    vertex, interface, exact, denominator = vertex_parts(vertices, faces, which, len(regions), grid, lengths)
    return InterfaceParts(regions, tuple(f"{names[a]}|{names[b]}" for a, b in regions.tolist()),
                          faces.astype(np.int32), np.asarray(which, dtype=np.int32).reshape(-1),
                          vertex.astype(np.int64), interface.astype(np.int32), _narrow(exact), denominator)


def _narrow(values: np.ndarray) -> np.ndarray:
    """Integers as int64 when they fit with room for sums, else Python integers (object)."""
    if values.dtype != object:
        return values
    fits = all(abs(int(v)) < 2**62 // max(1, len(values)) for v in values.tolist())
    return values.astype(np.int64) if fits else values
