"""The base element of a study: its configurations, its symmetry group, orbits under it, its tessellation."""

from __future__ import annotations

from fractions import Fraction
from itertools import product

import pytest

from cospherical import Box
from cospherical.core.base_element import ELEMENTS, base_element
from cospherical.errors import InputError

CUBE, BRICK, SQUARE_BRICK = (Box.parse(b) for b in (["1", "1", "1"], ["1", "2", "4"], ["1", "2", "2"]))
# Each shape's isometries, by elementary geometry: the cube's 48; a box with two equal edges 16, none 8;
# the right prism (a right isosceles triangle times a height) 4 in a cube, 2 when the legs differ; the square
# pyramid 8 (the square's), 4 on a rectangle; the corner tetrahedron of a cube the 6 permutations of its legs.
GROUP_ORDERS = {
    (CUBE, "cuboid"): 48, (SQUARE_BRICK, "cuboid"): 16, (BRICK, "cuboid"): 8,
    (CUBE, "prism"): 4, (BRICK, "prism"): 2, (CUBE, "pyramid"): 8, (BRICK, "pyramid"): 4,
    (CUBE, "tetrahedron"): 6, (SQUARE_BRICK, "tetrahedron"): 2, (BRICK, "tetrahedron"): 1,
}
# The shape's volume over its box's: the whole box, half of it, base x height / 3 with the apex at the centre, a corner.
VOLUMES = {"cuboid": 1, "prism": Fraction(1, 2), "pyramid": Fraction(1, 6), "tetrahedron": Fraction(1, 6)}


@pytest.mark.parametrize("box, name", GROUP_ORDERS)
def test_the_symmetries_are_the_shapes_isometries(box, name):
    element = base_element(name, box)
    symmetries = element.symmetries
    assert len(symmetries) == GROUP_ORDERS[box, name]
    corners = element.shape.corners
    assert symmetries[0].corner_map == tuple(range(len(corners)))  # identity first

    def squared(p, q):
        return sum(w * (Fraction(a) - Fraction(b)) ** 2 for w, a, b in zip(box.squared, p, q))

    for symmetry in symmetries:
        image = symmetry.corner_map
        assert sorted(image) == list(range(len(corners)))
        assert all(squared(corners[i], corners[j]) == squared(corners[image[i]], corners[image[j]])
                   for i in range(len(corners)) for j in range(i))


def test_one_object_per_element_box_and_policy_and_an_unknown_name_refused_at_once():
    assert base_element("prism", CUBE) is base_element("prism", Box.parse(["1", "1", "1"]))
    assert base_element("prism", CUBE) is not base_element("prism", CUBE, "none")
    assert set(ELEMENTS) == {"cuboid", "prism", "pyramid", "tetrahedron"}
    with pytest.raises(InputError, match="element 'cube': choose one of"):
        base_element("cube", CUBE)


@pytest.mark.parametrize("name", ["prism", "pyramid", "tetrahedron"])
def test_orbits_of_every_bisection_code(name):
    element = base_element(name, CUBE)
    codes = ["".join(digits) for digits in product("08", repeat=element.edges)]
    reps, moves = element.orbit_representatives(codes)
    assert element.orbit_representatives(codes, "numpy") == (reps, moves)
    for code, rep, move in zip(codes, reps, moves):
        images = {s.code(code) for s in element.symmetries}
        assert rep == min(images) and element.symmetries[move].code(code) == rep
    # Burnside's lemma: the orbits are the group's average number of fixed codes
    fixed = sum(s.code(code) == code for s in element.symmetries for code in codes)
    assert len(set(reps)) * len(element.symmetries) == fixed


@pytest.mark.parametrize("name", ELEMENTS)
def test_every_point_on_every_edge_tessellates_the_shape(name):
    element = base_element(name, BRICK)
    configuration = element.configuration("8" * element.edges)
    assert len(configuration.steiner) == element.edges and all(t == Fraction(1, 2) for t in configuration.steiner)
    tessellation = element.tessellate(configuration)
    assert sum(e.polyhedron.unit_volume for e in tessellation.elements) == VOLUMES[name]
    with pytest.raises(InputError):
        element.configuration("8" * (element.edges + 1))
