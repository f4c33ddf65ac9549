"""One element's exact pieces (cospherical.mesh.dual.pieces): on a cuboid of any box, against its closed form."""

from __future__ import annotations

from fractions import Fraction

from hypothesis import given, settings
from hypothesis import strategies as st

from cospherical.mesh.dual import element_pieces

CORNERS = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
FACES = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
LENGTH = st.fractions(Fraction(1, 8), 8, max_denominator=12)


@settings(max_examples=10, deadline=None)
@given(st.tuples(LENGTH, LENGTH, LENGTH), st.tuples(*[st.integers(1, 3)] * 3))
def test_a_cuboid_element_gives_its_voronoi_pieces_in_any_box(lengths, cells):
    """A cuboid of (p, q, r) unit steps in a box of squared lengths w: its Voronoi cells are the eighths, so each
    vertex gets 1/8 of the volume, an edge along k gets the quarter face normal to it over its length, and
    each face lies in its coordinate plane with a quarter of its area per vertex; with the sum rule
    (pyramids): twice the volume is the edges' area times length summed over both ends."""
    squared = tuple(x * x for x in lengths)
    points = {n: tuple(Fraction(c * s) for c, s in zip(corner, cells)) for n, corner in enumerate(CORNERS)}
    center = tuple(Fraction(s, 2) for s in cells)
    pieces = element_pieces(points, FACES, center, squared)
    p, q, r = cells
    assert pieces.volumes == {n: Fraction(p * q * r, 8) for n in range(8)}
    assert len(pieces.edges) == 12
    for (u, v), share in pieces.edges.items():
        k = next(a for a in range(3) if CORNERS[u][a] != CORNERS[v][a])
        others = [a for a in range(3) if a != k]
        # area / length over a*b*c: (1/4 of the face normal to k) / (its length) over the product of lengths
        face = Fraction(cells[others[0]] * cells[others[1]], 4)
        assert share == face / (cells[k] * squared[k])
    assert len(pieces.boundary) == 6
    for (axis, value), shares in pieces.boundary.items():
        others = [a for a in range(3) if a != axis]
        assert value in (0, cells[axis]) and len(shares) == 4
        assert set(shares.values()) == {Fraction(cells[others[0]] * cells[others[1]], 4)}
