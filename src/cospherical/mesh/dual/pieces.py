"""One element's exact dual pieces: its shares of the dual faces of its edges and of its vertices' control volumes.

Inside an element with circumcenter ``c`` the dual face of its edge ``(u, v)`` is the
polygon ``m, f1, c, f2`` (``m`` the edge's midpoint, ``f1, f2`` the centres of the
circles of the two faces at the edge), and the vertex ``u`` gets the pyramids over
those pieces, of volume ``|e| * area / 6``::

            v
           /|\\          one face at edge (u, v), seen from outside:
          / | \\         f is the face's circle centre; the triangle
         /  m--f        (m, f, c) is the face's share of the dual
        /   |   \\       face of (u, v); c lies behind the page
       u----+----

A piece is signed (negative where ``c`` or ``f`` lies beyond the face or the edge), so
the sums are right for every element list and never hide a non-Delaunay mesh: its
coefficients come out negative, and are counted.  Only polygon edges of element
faces are edges; a diagonal inside a polygon face has a dual face of zero area.

Exact: with points ``(s*a, t*b, u*c)`` in unit coordinates and the squared lengths
``w = (a^2, b^2, c^2)`` (rational also for sqrt boxes), a face centre is
``c - (d.N / sum N_k^2/w_k) * N/w`` and a triangle's piece of ``area / length`` is
``a*b*c * (x_u - x_v).((f - m) x (c - m)) / (2 |e|^2)``: a rational times ``a*b*c``.
Volumes are rationals times ``a*b*c`` too, boundary areas rationals times the
product of the two lengths of their plane (kept per axis: on a sqrt box the three
products are different square roots).  Signs (negative coefficients) are
therefore decided on the rationals.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Mapping, Sequence

from ...core.geometry import Rational, determinant, plane_normal, plane_projection, sub

__all__ = ["ElementPieces", "Point", "element_pieces"]

Point = tuple[Rational, Rational, Rational]


@dataclass(frozen=True)
class ElementPieces:
    """One element's exact pieces, in a frame where the box has squared lengths ``w``.

    ``edges``: ``{(u, v): q}`` with ``u < v`` node ids and ``q`` the element's share of
    the edge's ``area / length`` over ``a*b*c``; ``volumes``: ``{u: q}`` each vertex's
    share of the element's volume over ``a*b*c``; ``boundary``: for each face that
    lies in a coordinate plane ``(axis, value)``, ``{u: q}`` each vertex's share of the
    face's area over the product of the plane's two lengths.
    """

    edges: dict[tuple[int, int], Fraction]
    volumes: dict[int, Fraction]
    boundary: dict[tuple[int, Fraction], dict[int, Fraction]]


def element_pieces(points: Mapping[int, Point], faces: Sequence[Sequence[int]], center: Point,
                   squared: Sequence[Fraction]) -> ElementPieces:
    """The exact dual pieces of one co-spherical element.

    ``points``: node id -> unit coordinates; ``faces``: the element's face cycles,
    counter-clockwise seen from outside; ``center``: its circumcenter in unit
    coordinates; ``squared``: the box's squared lengths.

    Examples
    --------
    >>> cube = {n: tuple(Fraction(x) for x in p) for n, p in enumerate(
    ...     [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)])}
    >>> faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    >>> half = Fraction(1, 2)
    >>> pieces = element_pieces(cube, faces, (half, half, half), (1, 1, 1))
    >>> pieces.edges[0, 1], pieces.volumes[0], len(pieces.edges), pieces.boundary[2, 0][0]
    (Fraction(1, 4), Fraction(1, 8), 12, Fraction(1, 4))
    """
    # Integers throughout, one fraction per edge, vertex and boundary share: coordinates times D
    # (midpoints stay integers), squared lengths as integer weights W = lam * w, a face centre times
    # D * S (S per face); every face's sums are brought to the common S^2 of the element (the lcm of
    # its faces'), so that the pieces are summed as integers and divided once
    w = tuple(Fraction(x) for x in squared)
    lam = math.lcm(*(x.denominator for x in w))
    weight = tuple(int(x * lam) for x in w)
    inverse = tuple(math.lcm(*weight) // x for x in weight)
    scale = 2 * math.lcm(*(x.denominator for p in (*points.values(), center) for x in p))
    ip = {n: tuple(x.numerator * (scale // x.denominator) for x in p) for n, p in points.items()}
    ic = tuple(x.numerator * (scale // x.denominator) for x in center)
    # per face: its S^2, its edges' (key, piece, squared length), each vertex's volume and boundary area sums
    measured: list[tuple[int, list[tuple[tuple[int, int], int, int]], dict[int, int],
                         tuple[int, Fraction] | None, dict[int, int]]] = []
    for cycle in faces:
        p0, p1, p2 = (ip[n] for n in cycle[:3])
        normal = plane_normal(p0, p1, p2)  # no three points of a circle are collinear
        face_center, s = plane_projection(ic, p0, normal, inverse)  # the face's circle centre, times D * S
        cs = tuple(x * s for x in ic)
        plane = [k for k in range(3) if normal[k] != 0]
        in_plane = None
        if len(plane) == 1:  # in a coordinate plane: it may be on the domain's boundary
            k = plane[0]
            in_plane = (k, Fraction(p0[k], scale))
            outward = 1 if normal[k] > 0 else -1
        face_edges = []
        face_volume: dict[int, int] = {}
        face_area: dict[int, int] = {}
        for u, v in zip(cycle, (*cycle[1:], cycle[0])):
            xu, xv = ip[u], ip[v]
            mid = tuple((xu[k] + xv[k]) // 2 * s for k in range(3))
            along = sub(xu, xv)
            piece = determinant(along, sub(face_center, mid), sub(cs, mid))  # times D^3 S^2
            length2 = sum(weight[k] * along[k] * along[k] for k in range(3))  # times lam D^2
            face_edges.append(((u, v) if u < v else (v, u), piece, length2))
            face_volume[u] = face_volume.get(u, 0) + piece
            face_volume[v] = face_volume.get(v, 0) + piece
            if in_plane is not None:
                # triangles (x_u, m, f) and (m, x_v, f): equal areas, half a base each (times D^2 S^2)
                xs = tuple(x * s for x in xu)
                area = outward * plane_normal(xs, mid, face_center)[k]
                face_area[u] = face_area.get(u, 0) + area
                face_area[v] = face_area.get(v, 0) + area
        measured.append((s * s, face_edges, face_volume, in_plane, face_area))
    common = math.lcm(*(s2 for s2, *_ in measured))
    edge_sums: dict[tuple[int, int], list[int]] = {}  # key -> [piece sum times common S^2, squared length]
    volume_sums = {n: 0 for n in points}
    area_sums: dict[tuple[int, Fraction], dict[int, int]] = {}
    for s2, face_edges, face_volume, in_plane, face_area in measured:
        factor = common // s2
        for key, piece, length2 in face_edges:
            edge_sums.setdefault(key, [0, length2])[0] += piece * factor
        for node, total in face_volume.items():
            volume_sums[node] += total * factor
        if in_plane is not None:
            sums = area_sums.setdefault(in_plane, {})
            for node, total in face_area.items():
                sums[node] = sums.get(node, 0) + total * factor
    edges = {key: Fraction(total * lam, 2 * scale * common * length2) for key, (total, length2) in edge_sums.items()}
    volumes = {node: Fraction(total, 12 * scale ** 3 * common) for node, total in volume_sums.items()}
    boundary = {plane: {node: Fraction(total, 2 * scale * scale * common) for node, total in sums.items()}
                for plane, sums in area_sums.items()}
    return ElementPieces(edges, volumes, boundary)

