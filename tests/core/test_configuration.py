from fractions import Fraction

import pytest

from cospherical import Box, Configuration, InputError, Length


@pytest.mark.parametrize(
    "text, squared, canonical",
    [
        ("1", 1, "1"),
        ("1.4142", Fraction(7071, 5000) ** 2, "1.4142"),
        ("3/2", Fraction(9, 4), "1.5"),
        ("sqrt(2)", 2, "sqrt(2)"),
        (" sqrt( 9/4 ) ", Fraction(9, 4), "1.5"),
        ("2*sqrt(2)", 8, "sqrt(8)"),
        ("1/3", Fraction(1, 9), "1/3"),
    ],
)
def test_lengths_are_exact(text, squared, canonical):
    length = Length.parse(text)
    assert length.squared == squared
    assert length.text == canonical


@pytest.mark.parametrize("text", ["0", "-1", "nan", "inf", "abc", "sqrt(-2)", "sqrt(0)", "1/0", "", "sqrt()"])
def test_bad_lengths_name_the_value(text):
    with pytest.raises(InputError, match="box length"):
        Length.parse(text)


def test_float_lengths_are_refused():
    with pytest.raises(InputError, match="exact"):
        Length.parse(1.5)


@pytest.mark.parametrize(
    "steiner, message",
    [
        ({0: "0"}, "edge 0"),
        ({3: "1"}, "edge 3"),
        ({5: "3/2"}, "edge 5"),
        ({12: "1/2"}, "edge 12"),
        ({-1: "1/2"}, "edge -1"),
        ({"x": "1/2"}, "edge 'x'"),
        ({2: "half"}, "edge 2"),
    ],
)
def test_bad_steiner_points_name_the_value(steiner, message):
    with pytest.raises(InputError, match=message):
        Configuration.from_steiner(("1", "1", "1"), steiner)


@pytest.mark.parametrize("code", ["", "80000000000", "8000000000000", "80000000000g", 800000000000])
def test_bad_codes_name_the_value(code):
    with pytest.raises(InputError, match="configuration code"):
        Configuration.from_code(code)


def test_bad_point_policy():
    with pytest.raises(InputError, match="face-point policy"):
        Configuration.from_code("000000000000", face_points="all")


def test_box_needs_three_lengths():
    with pytest.raises(InputError, match="three lengths"):
        Box.parse(["1", "2"])


def test_code_round_trip_and_non_dyadic():
    cfg = Configuration.from_code("1234567890ab")
    assert cfg.code == "1234567890ab"
    assert cfg.steiner[1] == Fraction(2, 16) and cfg.steiner[9] is None
    assert Configuration.from_steiner(("1", "1", "1"), {0: "1/3"}).code is None


def test_parameters_run_along_the_axis():
    # Edge 2 joins corners 2 (a,b,0) and 3 (0,b,0); t is measured from the lower x.
    nodes = Configuration.from_steiner(("1", "1", "1"), {2: "1/4"}).nodes()
    assert nodes[10] == (Fraction(1, 4), 1, 0)


def test_face_points_need_four_split_edges_with_matching_opposites():
    all_mid = Configuration.from_code("888888888888").nodes()
    assert set(all_mid) == set(range(27))
    assert all_mid[24] == (Fraction(1, 2), Fraction(1, 2), 0)
    assert all_mid[26] == (Fraction(1, 2),) * 3
    # Face 24 (z = 0) has edges 0, 1, 2, 3: 0 and 2 run along x, 1 and 3 along y.
    crossing = Configuration.from_steiner(("1", "1", "1"), {0: "1/4", 2: "1/4", 1: "3/4", 3: "3/4"}).nodes()
    assert crossing[24] == (Fraction(1, 4), Fraction(3, 4), 0)
    assert 26 not in crossing
    skewed = Configuration.from_steiner(("1", "1", "1"), {0: "1/4", 2: "1/2", 1: "3/4", 3: "3/4"}).nodes()
    assert 24 not in skewed
    none = Configuration.from_code("888888888888", face_points="none").nodes()
    assert set(none) == set(range(20))
