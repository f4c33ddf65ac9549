"""Configurations: exact lengths, Steiner points and codes, face points as data, the whole-point-set code."""

from fractions import Fraction

import pytest
from hypothesis import given, settings
from strategies import configurations

from cospherical import Box, Configuration, InputError, Length, tessellate

CUBE = ("1", "1", "1")


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


def cells(tess) -> list[tuple]:
    """What a tessellation is, apart from how its configuration was written down."""
    return [(e.type.id, e.nodes, e.mirrored, e.polyhedron) for e in tess.elements]


def test_explicit_faces_place_exactly_those_points():
    cfg = Configuration.from_code("888888888888", CUBE, faces=[0, 4])
    assert cfg.face_points == "explicit" and cfg.point_faces == frozenset({0, 4}) and not cfg.has_body_point
    assert set(cfg.nodes()) == set(range(20)) | {20, 24}
    assert cfg.nodes()[24] == (Fraction(1, 2), Fraction(1, 2), 0)
    assert cfg.code == cfg.point_set_code == "888888888888+f04"


def test_face_points_sit_where_the_cut_lines_cross():
    # Face 4 (z = 0): edges 0, 2 along x at 1/4, edges 1, 3 along y at 3/4.
    cfg = Configuration.from_steiner(CUBE, {0: "1/4", 2: "1/4", 1: "3/4", 3: "3/4"}, faces=[4])
    assert cfg.nodes()[24] == (Fraction(1, 4), Fraction(3, 4), 0)
    assert cfg.code == "4c4c00000000+f4"


def test_policies_are_shorthands_for_explicit_sets():
    octree = Configuration.from_code("888888888888", CUBE)
    assert octree.code == "888888888888" and octree.point_set_code == "888888888888+f012345b"
    assert octree.point_faces == frozenset(range(6)) and octree.has_body_point
    none = Configuration.from_code("888888888888", CUBE, face_points="none")
    assert none.point_set_code == "888888888888+f" and none.point_faces == frozenset()
    assert octree.explicit().nodes() == octree.nodes() and octree.explicit().face_points == "explicit"
    assert Configuration.from_code("888800000000", CUBE).point_set_code == "888800000000+f4"


def test_a_suffixed_code_names_every_point_whatever_the_policy():
    for policy in ("octree", "none", "explicit"):
        cfg = Configuration.from_code("888888888888+f25", CUBE, face_points=policy)
        assert cfg.point_faces == frozenset({2, 5}) and cfg.code == "888888888888+f25"


def test_explicit_policy_needs_a_suffix():
    with pytest.raises(InputError, match="suffix"):
        Configuration.from_code("888888888888", CUBE, face_points="explicit")


@pytest.mark.parametrize(
    "code, needle",
    [
        ("888888888888+f66", "face"),
        ("888888888888+f44", "twice"),
        ("888888888888+f40", "increasing"),
        ("888888888888+f6", "face"),
        ("888888888888+", "suffix"),
        ("888888888888+g0", "suffix"),
        ("888888888888f0", "configuration code"),
        ("888888888888+f0+f1", "suffix"),
        ("888888888888+fb", "body point"),
        ("888888888888+f01234b", "body point"),
        ("800000000000+f0", "face 0"),
        ("888888888888+F0", "suffix"),
    ],
)
def test_malformed_codes_are_refused(code, needle):
    with pytest.raises(InputError, match=needle):
        Configuration.from_code(code, CUBE)


@pytest.mark.parametrize(
    "steiner, faces, needle",
    [
        ({0: "1/2", 4: "1/2", 8: "1/2"}, [0], "face 0 .*edge 9"),  # edge 9 is not split
        ({0: "1/4", 4: "1/2", 8: "1/2", 9: "1/2"}, [0], "face 0 .*edges 0 and 4 .*1/4 .*1/2"),
        ({}, [7], "face 7"),
        ({0: "1/2", 4: "1/2", 8: "1/2", 9: "1/2"}, [0, 0], "face 0 .*twice"),
    ],
)
def test_inadmissible_face_points_name_the_face(steiner, faces, needle):
    with pytest.raises(InputError, match=needle):
        Configuration.from_steiner(CUBE, steiner, faces=faces)


def test_the_body_point_needs_all_six_faces():
    Configuration.from_code("888888888888", CUBE, faces=range(6), body=True)
    with pytest.raises(InputError, match="body point"):
        Configuration.from_code("888888888888", CUBE, faces=range(5), body=True)
    with pytest.raises(InputError, match="body point"):
        Configuration.from_code("888888888888", CUBE, face_points="octree", body=True)


@settings(max_examples=60, deadline=None)
@given(configurations(dyadic=True))
def test_a_policy_and_its_explicit_point_set_tessellate_identically(cfg):
    explicit = cfg.explicit()
    assert explicit.nodes() == cfg.nodes()
    assert cells(tessellate(explicit)) == cells(tessellate(cfg))


@settings(max_examples=200, deadline=None)
@given(configurations(dyadic=True))
def test_whole_point_set_codes_round_trip(cfg):
    code = cfg.point_set_code
    again = Configuration.from_code(code, cfg.box)
    assert again == cfg.explicit() and again.point_set_code == code and again.nodes() == cfg.nodes()
    assert Configuration.from_code(cfg.code, cfg.box, cfg.face_points) == cfg
