"""The device file: the issue's example read as written, bad files refused with one line, exit 2, nothing written."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import pytest

from cospherical.cli import main
from cospherical.errors import FormatError
from cospherical.formats.device_file import MAX_DEVICE_BYTES, parse_device, read_device

EXAMPLES = Path(__file__).parents[2] / "examples" / "devices"

_MOS = (EXAMPLES / "mos-capacitor.yaml").read_text()


def test_the_mos_capacitor_is_read_as_written():
    device = read_device(EXAMPLES / "mos-capacitor.yaml")
    assert [r.name for r in device.regions] == ["substrate", "oxide"]
    assert device.regions[0].boxes == ((0, 0, 0, 1, 1, Fraction(3, 4)),)  # 0.75 is the decimal 3/4, not a float
    assert [(c.name, c.region, c.axis) for c in device.contacts] == [("bulk", "substrate", 2), ("gate", "oxide", 2)]
    assert device.refine[0].values == (0, 0, 1, Fraction(3, 4)) and device.levels == 5


_REGION = "regions:\n  - {name: si, material: Si, boxes: [[0, 0, 0, 1, 1, 1]]}\n"


@pytest.mark.parametrize("text, needle", [
    ("device: d\nregions: []\n", "regions"),
    ("device: d\n" + _REGION + "  - {name: si, material: Ox, boxes: [[0, 0, 1, 1, 1, 2]]}\n", "two regions named 'si'"),
    ("device: d\n" + _REGION + "  - {name: ox, material: Ox, boxes: [[0, 0, 0.5, 1, 1, 2]]}\n",
     "region 'ox' box 0 overlaps region 'si' box 0"),
    ("device: d\n" + _REGION + "contacts: [{name: c, region: metal, box: [0, 0, 0, 1, 1, 0]}]\n",
     "contact 'c': region 'metal' is not a region"),
    ("device: d\n" + _REGION + "contacts: [{name: c, region: si, box: [0, 0, 0.5, 1, 1, 0.5]}]\n",
     "contact 'c': not on the boundary of region 'si'"),
    ("device: d\n" + _REGION + "  - {name: ox, material: Ox, boxes: [[3, 3, 3, 4, 4, 4]]}\n",
     "does not touch the rest of the device"),
    ("device: d\n" + _REGION + "  - {name: ox, material: Ox, boxes: [[1, 1, 1, 2, 2, 2]]}\n",
     "does not touch the rest"),  # touching along a corner only
    ("device: d\nregions:\n  - {name: si, material: Si, boxes: [[0, 0, 0, 1, 1, '1/3'], [0, 0, '1/3', 1, 1, 1]]}\n",
     "z1 = 1/3 is not resolved by any dyadic refinement of the bounding box"),
    ("device: d\nregions:\n  - {name: '../x', material: Si, boxes: [[0, 0, 0, 1, 1, 1]]}\n", "regions.0.name"),
    ("device: d\nregions: &a [*a]\n", "alias"),
    ("device: d\n" + _REGION + "levels: 99\n", "levels"),
    ("device: d\n" + _REGION + "refine: [{cone: [1, 2]}]\n", "refine"),
    ("x" * (MAX_DEVICE_BYTES + 1), "too large"),
    ("device: thin\nregions:\n  - {name: a, material: Si, boxes: [[0, 0, 0, 1, 1, '65535/65536']]}\n"
     "  - {name: b, material: Si, boxes: [[0, 0, '65535/65536', 1, 1, 1]]}\n", "above the bound"),
])
def test_bad_device_files_are_refused_with_one_line(tmp_path, capsys, text, needle):
    path = tmp_path / "device.yaml"
    path.write_text(text)
    out = tmp_path / "out"
    assert main(["mesh", "--device", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and needle in err, err
    assert not out.exists()


def test_a_device_does_not_take_a_tree_of_its_own(tmp_path, capsys):
    assert main(["mesh", "--device", str(EXAMPLES / "pn-diode.yaml"), "--refine", "point:0,0,0", "--levels", "1"]) == 2
    assert "--refine" in capsys.readouterr().err
    # the file says its balance: --balance was ignored without a word
    assert main(["mesh", "--device", str(EXAMPLES / "pn-diode.yaml"), "--balance", "edge"]) == 2
    assert "--balance" in capsys.readouterr().err
    # a device is meshed in one process (the devices page says why)
    assert main(["mesh", "--device", str(EXAMPLES / "pn-diode.yaml"), "--partitions", "2"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "--partitions" in err and "one process" in err, err


def test_numbers_stay_exact_and_names_are_data():
    device = parse_device("device: d\nregions:\n  - {name: 'a.b+c-1', material: 'x', boxes: [[0, 0, 0, 0.1, '1/2', 1e-1]]}\n")
    assert device.regions[0].boxes[0][3:] == (Fraction(1, 10), Fraction(1, 2), Fraction(1, 10))


@pytest.mark.parametrize("number", ["010", "1:30", "0x10", "0b11", "1_0", "-07"])
def test_an_integer_that_yaml_would_read_as_another_number_is_refused(number):
    # YAML 1.1 reads 010 as 8 and 1:30 as 90: a coordinate would silently be another number
    text = f"device: d\nregions:\n  - {{name: si, material: Si, boxes: [[0, 0, 0, {number}, 1, 1]]}}\n"
    with pytest.raises(FormatError, match="is not a decimal integer"):
        parse_device(text)
    assert parse_device(text.replace(number, "10")).regions[0].boxes[0][3] == 10  # plain digits are read as written
