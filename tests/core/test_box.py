"""The box and the cuboid's numbering, against VTK's own cells (an oracle nobody here wrote)."""

from fractions import Fraction

import pytest

from cospherical import InputError
from cospherical.core.box import CORNERS, EDGES, FACE_EDGES, FACES, Box, edge_axis


def _vtk_points(cell) -> list[tuple[Fraction, ...]]:
    coords = cell.GetParametricCoords()
    return [tuple(Fraction(coords[3 * i + j]) for j in range(3)) for i in range(cell.GetNumberOfPoints())]


@pytest.mark.oracle_vtk
def test_the_numbering_is_vtks_where_the_docstring_says():
    from vtkmodules.vtkCommonDataModel import vtkHexahedron, vtkTriQuadraticHexahedron

    ours = [tuple(map(Fraction, c)) for c in CORNERS]
    ours += [tuple((a + b) / 2 for a, b in zip(ours[p], ours[q])) for p, q in EDGES]
    ours += [tuple(sum(ours[c][axis] for c in face) / 4 for axis in range(3)) for face in FACES]
    ours.append((Fraction(1, 2),) * 3)
    theirs = _vtk_points(vtkTriQuadraticHexahedron())
    assert ours[:20] == theirs[:20] and ours[24:] == theirs[24:]
    assert theirs[20:24] == [ours[23], ours[21], ours[20], ours[22]]  # as core.box's docstring says
    hexahedron = vtkHexahedron()  # the faces of VTK's hexahedron, in another order
    assert {frozenset(face) for face in FACES} == {frozenset(hexahedron.GetFaceArray(f)) for f in range(6)}


def test_face_edges_and_axes():
    for face, edges in zip(FACES, FACE_EDGES):
        assert [k for k in range(12) if set(EDGES[k]) <= set(face)] == list(edges)
        assert len({edge_axis(k) for k in edges}) == 2  # a face spans two axes
    assert [edge_axis(k) for k in range(12)] == [0, 1, 0, 1, 0, 1, 0, 1, 2, 2, 2, 2]


def test_box_parses_exact_lengths_and_refuses_others():
    box = Box.parse(["1", "sqrt(2)", Fraction(3, 2)])
    assert box.squared == (1, 2, Fraction(9, 4)) and box.texts[:2] == ("1", "sqrt(2)")
    with pytest.raises(InputError, match="exactly three"):
        Box.parse(["1", "2"])
