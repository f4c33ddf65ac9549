"""Face points as data, the whole-point-set code, and the octree-leaf family."""

from __future__ import annotations

import json
import random
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import pytest
from hypothesis import given, settings

from cospherical import Box, Configuration, InputError, tessellate
from cospherical.catalogue import catalogue_path, shipped_catalogue
from cospherical.cli import main
from cospherical.core.symmetry import box_symmetries, orbit_representatives
from cospherical.files.yamlio import dump_yaml, load_yaml
from cospherical.formats.patterns import load, pattern_name, write_patterns
from cospherical.studies.bisection import bisection_codes, run_study
from cospherical.studies.leaves import leaf_codes, run_leaves
from oracle import qhull_regions, qhull_regions_by_orbit
from strategies import configurations

CUBE = ("1", "1", "1")
ROOT = Path(__file__).resolve().parents[1]


def cospherical(*args):
    return subprocess.run([sys.executable, "-m", "cospherical", *args], capture_output=True, text=True)


def cells(tess) -> list[tuple]:
    """What a tessellation is, apart from how its configuration was written down."""
    return [(e.type.id, e.nodes, e.mirrored, e.polyhedron) for e in tess.elements]


# --- face points as data ---------------------------------------------------------------------------


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


def test_symmetries_map_face_points():
    box = Box.parse(CUBE)
    cfg = Configuration.from_steiner(box, {0: "1/4", 2: "1/4", 1: "3/4", 3: "3/4", 4: "1/4", 8: "1/2", 9: "1/2"},
                                     faces=[0, 4])
    images = set()
    for sym in box_symmetries(box):
        image = sym.configuration(cfg)
        assert image.code == sym.code(cfg.code) and image.point_faces == {sym.face_map[0], sym.face_map[4]}
        assert {sym.node_map[i]: sym.point(p) for i, p in cfg.nodes().items()} == image.nodes()
        images.add(image.code)
    representative, _ = orbit_representatives([cfg.code], box_symmetries(box))
    assert representative[0] in images


# --- hypothesis: shorthands and codes ---------------------------------------------------------------


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


# --- the Qhull oracle on face subsets at general positions -------------------------------------------


@pytest.mark.oracle_qhull
def test_random_face_subsets_at_sixteenths_match_qhull():
    rng = random.Random(1313)
    boxes = [CUBE, ("1", "2", "4"), ("1", "sqrt(2)", "sqrt(2)"), ("3", "1", "2")]
    checked = 0
    while checked < 300:
        steiner = {}
        for axis_edges in ((0, 2, 4, 6), (1, 3, 5, 7), (8, 9, 10, 11)):
            t = Fraction(rng.randint(1, 15), 16)
            for k in axis_edges:
                roll = rng.random()
                if roll < 0.6:
                    steiner[k] = t  # equal parameters on parallel edges: admissible faces
                elif roll < 0.8:
                    steiner[k] = Fraction(rng.randint(1, 15), 16)
        admissible = sorted(Configuration.from_steiner(CUBE, steiner).admissible_faces)
        if not admissible:
            continue
        faces = [f for f in admissible if rng.random() < 0.5]
        body = len(faces) == 6 and rng.random() < 0.5
        cfg = Configuration.from_steiner(rng.choice(boxes), steiner, faces=faces, body=body)
        ours = {frozenset(e.nodes) for e in tessellate(cfg).elements}
        assert ours == qhull_regions(cfg.real_nodes()), (cfg.box.texts, cfg.point_set_code)
        checked += 1


# --- the leaf family -------------------------------------------------------------------------------


def test_the_leaf_family():
    codes = leaf_codes()
    assert len(codes) == len(set(codes)) == 6210 == sum(
        2 ** len(Configuration.from_code(code[:12]).admissible_faces) for code in bisection_codes())
    for code in codes[::11]:
        cfg = Configuration.from_code(code)
        assert cfg.code == code and not cfg.has_body_point and cfg.point_faces <= cfg.admissible_faces


@pytest.mark.oracle_qhull
@pytest.mark.parametrize("box", [CUBE, ("1", "2", "4")])
def test_every_leaf_configuration_matches_qhull(box):
    """Every configuration of the leaf family, as the study gives it (through its orbit's
    representative), against ``qdelaunay Qz Fv``.  A configuration whose point set is that
    of an octree- or none-policy bisection configuration (no face point, or exactly the
    admissible ones short of all six) is checked by test_delaunay_oracle for both boxes:
    here only that the point sets coincide."""
    study = run_leaves(Box.parse(box), criteria=("optimal",))
    new = []
    for code in study.codes:
        cfg = Configuration.from_code(code, box)
        if not cfg.point_faces:
            assert cfg.nodes() == Configuration.from_code(code[:12], box, face_points="none").nodes()
        elif cfg.point_faces == cfg.admissible_faces and len(cfg.point_faces) < 6:
            assert cfg.nodes() == Configuration.from_code(code[:12], box).nodes()
        else:
            new.append(cfg)
    assert len(new) == 921
    # Qhull once per orbit, its regions carried to each member by an isometry checked exactly
    for cfg, regions in zip(new, qhull_regions_by_orbit(new, box_symmetries(Box.parse(box)))):
        tess = study.tessellation(cfg.code)
        assert tess.nodes == cfg.nodes()
        assert {frozenset(e.nodes) for e in tess.elements} == regions, cfg.code


def test_study_leaves_json_and_tables(tmp_path):
    result = cospherical("study", "leaves", "--box", "1", "2", "4", "--format", "json", "--out", str(tmp_path))
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    assert (data["study"], data["face_points"], data["configurations"], data["orbits"]) == \
        ("leaves", "explicit", 6210, 1012)
    assert (data["fvm_adequate"], data["fvm_adequate_open"]) == (1720, 268)
    assert {c: data["criteria"][c]["total"] for c in data["criteria"]} == \
        {"optimal": 74901, "internal_faces": 74901, "internal_edges_and_faces": 75077}
    optimal = data["criteria"]["optimal"]
    assert optimal["total"] == sum(t["count"] for t in optimal["types"].values())
    other = data["compared_with"]
    assert (other["study"], other["face_points"], other["configurations"]) == ("bisection", "octree", 4096)
    assert other["criteria"]["optimal"]["total"] == 45581
    assert json.loads((tmp_path / "leaves-1x2x4.json").read_text()) == data
    committed = ROOT / "patterns" / "leaves-1x2x4.yaml"
    assert (tmp_path / "leaves-1x2x4.yaml").read_bytes() == committed.read_bytes()


def test_leaf_tables_pass_check_and_look_up_by_whole_point_set_code(tmp_path):
    # The committed tables are regenerated byte for byte (test_study, test above); checking
    # them whole here would cost half a minute of YAML parsing, so a table of every 31st
    # leaf configuration of each box goes through the same `cospherical check`.
    sample = leaf_codes()[::31]
    paths = []
    for box in (CUBE, ("1", "2", "4")):
        study = run_study("leaves", Box.parse(box), sample, "explicit")
        paths.append(tmp_path / f"{pattern_name('leaves', box, 'explicit')}.yaml")
        write_patterns(study, paths[-1], shipped_catalogue()["version"])
    result = cospherical("check", str(catalogue_path()), *map(str, paths))
    assert result.returncode == 0, result.stderr
    assert result.stdout.count(f"{len(sample)} configurations") == 2
    table = load(paths[0])
    assert table.header["face_points"] == "explicit" and table.header["study"] == "leaves"
    for code in sample[::7]:
        tess = tessellate(Configuration.from_code(code))
        assert table.elements(code) == [
            {"type": e.type.id, "nodes": list(e.nodes), "circumcenter": list(tess.circumcenter(e)),
             **({"mirror": True} if e.mirrored else {})}
            for e in tess.elements
        ], code


@pytest.mark.parametrize(
    "key, needle",
    [
        ("800000000000+f0", "configurations/800000000000+f0: face 0"),  # edges 4, 8, 9 are not split
        ("888800000000+f44", "configurations"),  # not a whole-point-set code: the schema refuses it
        ("888800000000+f4b", "configurations/888800000000+f4b: body point"),
    ],
)
def test_leaf_tables_with_bad_codes_fail_check_in_one_line(tmp_path, capsys, key, needle):
    path = tmp_path / "leaves.yaml"
    write_patterns(run_study("leaves", Box.parse(CUBE), ["888800000000+f4", "000000000000+f"], "explicit"), path,
                   shipped_catalogue()["version"])
    data = load_yaml(path)
    data["configurations"][key] = data["configurations"].pop("888800000000+f4")
    dump_yaml(data, path)
    assert main(["check", str(path)]) == 2
    out, err = capsys.readouterr()
    assert len(err.strip().splitlines()) == 1 and needle in err, err


# --- the command line ------------------------------------------------------------------------------


def test_tessellate_with_faces_on_the_command_line():
    by_flag = cospherical("tessellate", "--box", "1", "1", "1", "--code", "888888888888", "--faces", "0", "4")
    assert by_flag.returncode == 0, by_flag.stderr
    data = json.loads(by_flag.stdout)
    assert data["code"] == "888888888888+f04" and data["face_points"] == "explicit"
    assert data["faces"] == [0, 4] and data["body_point"] is False and data["point_set_code"] == data["code"]
    assert set(data["nodes"]) == {str(i) for i in range(20)} | {"20", "24"}
    by_code = cospherical("tessellate", "--box", "1", "1", "1", "--code", "888888888888+f04")
    assert by_code.stdout == by_flag.stdout
    by_steiner = cospherical("tessellate", "--box", "1", "1", "1", "--steiner", *(f"{k}:1/2" for k in range(12)),
                             "--faces", "0", "4")
    assert json.loads(by_steiner.stdout)["elements"] == data["elements"]


def test_no_faces_given_explicitly_is_policy_none():
    explicit = json.loads(cospherical("tessellate", "--box", "1", "2", "4", "--code", "888888888888", "--faces").stdout)
    none = json.loads(cospherical("tessellate", "--box", "1", "2", "4", "--code", "888888888888",
                                  "--face-points", "none").stdout)
    assert explicit["code"] == "888888888888+f" and none["code"] == "888888888888"
    assert explicit["point_set_code"] == none["point_set_code"] == "888888888888+f"
    assert explicit["elements"] == none["elements"] and explicit["nodes"] == none["nodes"]


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--code", "800000000000", "--faces", "0"], "face 0"),
        (["--steiner", "0:1/4", "4:1/2", "8:1/2", "9:1/2", "--faces", "0"], "different parameters"),
        (["--code", "888888888888", "--faces", "0", "0"], "twice"),
        (["--code", "888888888888", "--faces", "6"], "face"),
        (["--code", "888888888888", "--faces", "x"], "face"),
        (["--code", "888888888888+f4x"], "suffix"),
        (["--code", "888888888888+f44"], "twice"),
        (["--code", "888888888888+f"], None),
        (["--code", "888888888888+f0", "--faces", "4"], "suffix"),
        (["--code", "888888888888", "--faces", "0", "--face-points", "none"], "not allowed"),
        (["--code", "888888888888", "--body"], "body point"),
    ],
)
def test_bad_face_points_on_the_command_line_exit_2_in_one_line(args, needle, capsys):
    # in-process (test_cli runs the same error path as a subprocess): a dozen interpreter starts saved
    status = main(["tessellate", "--box", "1", "1", "1", *args])
    out, err = capsys.readouterr()
    if needle is None:  # the empty suffix is a valid code
        assert status == 0, err
        return
    assert status == 2 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0] and "Traceback" not in err, err
