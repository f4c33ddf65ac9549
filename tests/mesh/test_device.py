"""A device built in Python is held to the device file's rules (names, exact coordinates, shapes), and names
and contacts that would clash in a solver's file are refused: one InputError line each."""

from __future__ import annotations

from fractions import Fraction

import pytest

from cospherical.errors import InputError
from cospherical.mesh.device import Contact, Device, Region, device_layout
from cospherical.mesh.octree import parse_shape

F = Fraction
UNIT = (F(0), F(0), F(0), F(1), F(1), F(1))


def _device(regions=(Region("si", "Si", (UNIT,)),), contacts=(), refine=(), name="d") -> Device:
    return Device(name, tuple(regions), tuple(contacts), tuple(refine), 1)


def test_a_device_of_integers_texts_and_shape_texts_is_the_device_of_fractions_and_shapes():
    # what a user writes in Python, read as the file reader reads it (int / int was a float: AttributeError)
    loose = _device([Region("si", "Si", [[0, 0, 0, 2, 1, "1/2"]]), Region("ox", "SiO2", [(0, 0, "0.5", 2, 1, 1)])],
                    [Contact("gate", "ox", [0, 0, 1, 2, 1, 1])], ["point:1,0.5,0.5"])
    exact = _device([Region("si", "Si", ((F(0), F(0), F(0), F(2), F(1), F(1, 2)),)),
                     Region("ox", "SiO2", ((F(0), F(0), F(1, 2), F(2), F(1), F(1)),))],
                    [Contact("gate", "ox", (F(0), F(0), F(1), F(2), F(1), F(1)))], [parse_shape("point:1,0.5,0.5")])
    assert device_layout(loose).device == device_layout(exact).device == exact


@pytest.mark.parametrize("device, needle", [
    (_device([Region("si", "Si", ((0.0, 0, 0, 1, 1, 1),))]), "not a float"),
    (_device([Region("si", "Si", ((0, 0, 0, 1, 1, float("nan")),))]), "not a float"),
    (_device([Region("si", "Si", ((0, 0, 0, 1, 1),))]), "six coordinates"),
    (_device([Region("si", "Si", ((0, 0, 0, 1, 1, True),))]), "not a number"),
    (_device([Region("si", "Si", (UNIT,))], [Contact("c", "si", (0, 0, 0))]), "six coordinates"),
    (_device([Region("si", "Si", (UNIT,))], refine=[5]), "no kind"),
    (_device([Region("../../etc/passwd", "Si", (UNIT,))]), "region name '../../etc/passwd'"),
    (_device([Region("si", "Si\n\x1b[2J", (UNIT,))]), "material name 'Si\\n\\x1b[2J'"),
    (_device([Region(["si"], "Si", (UNIT,))]), "region name ['si']"),
    (_device([Region("si", "Si", (UNIT,))], name="<script>"), "device name '<script>'"),
    (_device(["si"]), "is not a Region"),
    # one name space: Gmsh's physical names, meshio's field data and DEVSIM name one thing each
    (_device([Region("si", "Si", (UNIT,)), Region("c", "Si", ((F(1), F(0), F(0), F(2), F(1), F(1)),))],
             [Contact("c", "si", (F(0), F(0), F(0), F(0), F(1), F(1)))]), "a region and a contact both named 'c'"),
    (_device([Region("si", "Si", (UNIT,))], [Contact("c", "si", (F(0), F(0), F(0), F(0), F(1), F(1))),
                                             Contact("e", "si", (F(0), F(0), F(1, 2), F(0), F(1), F(1)))]),
     "contact 'e' overlaps contact 'c'"),
])
def test_a_device_object_is_held_to_the_device_files_rules(device, needle):
    with pytest.raises(InputError) as raised:
        device_layout(device)
    assert needle in str(raised.value) and "\n" not in str(raised.value), raised.value


def test_contacts_that_only_touch_are_two_contacts():
    layout = device_layout(_device([Region("si", "Si", (UNIT,))],
                                   [Contact("c", "si", (F(0), F(0), F(0), F(0), F(1, 2), F(1))),
                                    Contact("e", "si", (F(0), F(1, 2), F(0), F(0), F(1), F(1)))]))
    assert len(layout.contacts) == 2
