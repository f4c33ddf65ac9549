"""``cospherical check``, the deep check of catalogues and pattern tables: good files pass, each kind of damage
is one line naming it."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
from commands import cospherical, one_clean_line

from cospherical import Box
from cospherical.catalogue import catalogue_path, load_catalogue, shipped_catalogue
from cospherical.cli import main
from cospherical.files.yamlio import dump_yaml, load_yaml
from cospherical.formats.patterns import write_patterns
from cospherical.studies.engine import run_study

CUBE = ("1", "1", "1")
ROOT = Path(__file__).resolve().parents[2]


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


@pytest.fixture(scope="module")
def small_table(tmp_path_factory):
    """A pattern table of a few configurations of the 1x2x4 box, as data to break."""
    path = tmp_path_factory.mktemp("small") / "small.yaml"
    codes = ["000000000000", "800000000000", "880000000000", "888888888888"]
    study = run_study("bisection", Box.parse(("1", "2", "4")), codes)
    write_patterns(study, path, load_catalogue(catalogue_path())["version"])
    return load_yaml(path)


def write(tmp_path, name, data) -> str:
    path = tmp_path / name
    dump_yaml(data, path)
    return str(path)


def test_good_files_pass_the_deep_check(tmp_path, small_table):
    result = cospherical("check", str(ROOT / "catalogue" / "catalogue.yaml"), write(tmp_path, "good.yaml", small_table))
    assert result.returncode == 0, result.stderr
    assert "ok, catalogue of" in result.stdout and "ok, pattern table of 4 configurations" in result.stdout


@pytest.mark.parametrize(
    "edit, needle",
    [
        (lambda d: d["configurations"]["800000000000"]["optimal"][0].update(type="v5f5-ffffff"), "unknown element type"),
        (lambda d: d["configurations"]["800000000000"]["optimal"][0].update(nodes=[0, 1, 2, 3, 26]), "node 26 is not a point"),
        (lambda d: d["configurations"]["800000000000"]["optimal"][0].update(nodes=[0, 1, 2, 3, 40]), "800000000000"),
        (lambda d: d["configurations"]["800000000000"]["optimal"].pop(), "do not fill the box"),
        (lambda d: d["configurations"]["880000000000"]["optimal"][0].update(
            nodes=list(reversed(d["configurations"]["880000000000"]["optimal"][0]["nodes"]))), "configurations/880000000000"),
        (lambda d: d["configurations"]["800000000000"]["optimal"].append(  # a copy: a shared object is a YAML alias
            copy.deepcopy(d["configurations"]["800000000000"]["optimal"][0])), "do not fill the box"),
        (lambda d: d["configurations"]["000000000000"].update(internal_faces="internal_edges_and_faces"), "internal_faces"),
        (lambda d: d.update(box=["1", "0", "4"]), "box"),
        (lambda d: d.update(schema_version=2), "schema_version"),
    ],
)
def test_bad_pattern_tables_are_refused(tmp_path, small_table, edit, needle):
    data = copy.deepcopy(small_table)
    edit(data)
    one_clean_line(cospherical("check", write(tmp_path, "bad.yaml", data)), needle)


def test_repeated_configuration_codes_are_refused(tmp_path, small_table):
    text = Path(write(tmp_path, "good.yaml", small_table)).read_text().splitlines()
    start = text.index("configurations:") + 1
    end = next(i for i in range(start + 1, len(text)) if text[i].startswith("  '"))
    duplicated = text[: end] + text[start:end] + text[end:]
    path = tmp_path / "twice.yaml"
    path.write_text("\n".join(duplicated[:200]) + "\n")
    one_clean_line(cospherical("check", str(path)), "repeated key '000000000000'")


@pytest.mark.parametrize(
    "edit, needle",
    [
        (lambda d: d["types"].append(copy.deepcopy(d["types"][0])), "appears more than once"),
        (lambda d: d["types"][0].update(edges=99), "V/E/F"),
        (lambda d: d["types"][0]["reference_faces"][0].update(nodes=[0, 1, 9]), "reference_faces"),
        (lambda d: d["criteria"]["internal_faces"]["kept"].append("v4f4-000000"), "unknown type"),
        (lambda d: d["types"][0].pop("code"), "code"),
    ],
)
def test_bad_catalogues_are_refused(tmp_path, edit, needle):
    data = load_yaml(ROOT / "catalogue" / "catalogue.yaml")
    edit(data)
    one_clean_line(cospherical("check", write(tmp_path, "bad-catalogue.yaml", data)), needle)
