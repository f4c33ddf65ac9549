"""Studies: symmetry, the paper's tables, catalogue and pattern tables."""

from __future__ import annotations

import copy
import filecmp
import json
import subprocess
import sys
from pathlib import Path

import pytest

from cospherical import Box, Configuration, tessellate
from cospherical.catalogue import catalogue_path, load_catalogue
from cospherical.core.symmetry import box_symmetries
from cospherical.errors import FormatError
from cospherical.files.yamlio import dump_yaml, load_yaml
from cospherical.formats.check import check_catalogue, check_patterns
from cospherical.formats.patterns import load, pattern_name, write_patterns
from cospherical.paper import paper_comparison, paper_study_key
from cospherical.studies.bisection import bisection_codes, run_study
from cospherical.studies.summary import study_summary

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("lengths, order", [(("1", "1", "1"), 48), (("1", "2", "2"), 16), (("1", "2", "4"), 8)])
def test_group_orders(lengths, order):
    symmetries = box_symmetries(Box.parse(lengths))
    assert len(symmetries) == order
    assert sum(s.proper for s in symmetries) == order // 2
    # closed under inverse, and each node map is a bijection of 0..26
    assert all(sorted(s.node_map) == list(range(27)) for s in symmetries)
    assert all(s.inverse() in symmetries for s in symmetries)


@pytest.mark.parametrize("lengths", [("1", "1", "1"), ("1", "2", "4")])
def test_mapped_tessellations_equal_direct_ones(lengths):
    box = Box.parse(lengths)
    study = run_study("bisection", box, bisection_codes())
    for code in bisection_codes():
        direct = tessellate(Configuration.from_code(code, box))
        assert study.tessellation(code) == direct, code


def test_symmetry_maps_configurations_and_points():
    box = Box.parse(("1", "1", "1"))
    cfg = Configuration.from_steiner(box, {0: "1/4", 9: "3/16", 4: "1/4", 2: "1/4", 6: "1/4"})
    for sym in box_symmetries(box):
        image = sym.configuration(cfg)
        assert image.code == sym.code(cfg.code)
        nodes, image_nodes = cfg.nodes(), image.nodes()
        assert {sym.node_map[i]: sym.point(p) for i, p in nodes.items()} == image_nodes


@pytest.fixture(scope="module")
def paper_studies():
    return {
        key: run_study("bisection", Box.parse(box), bisection_codes())
        for key, box in (("bisection_A", ("1", "1", "1")), ("bisection_B", ("1", "2", "4")),
                         ("bisection_C", ("1", "1.4142", "1.4142")))
    }


@pytest.mark.parametrize("key", ["bisection_A", "bisection_B", "bisection_C"])
def test_paper_optimal_tables_row_by_row(paper_studies, key):
    study = paper_studies[key]
    assert paper_study_key(study_summary(study))[0] == key
    table = paper_comparison(study_summary(study), key)
    assert table["rows"], "no rows"
    for row in table["rows"]:
        assert row["paper"] == row["ours"], row
    assert table["total"]["paper"] == table["total"]["ours"]
    assert table["classes"]["paper"] == table["classes"]["ours"]


def test_exact_sqrt2_is_marked_as_a_different_box():
    study = run_study("bisection", Box.parse(("1", "sqrt(2)", "sqrt(2)")), bisection_codes())
    key, notes = paper_study_key(study_summary(study))
    assert key == "bisection_C" and "exact_sqrt2" in notes
    assert paper_comparison(study_summary(study), key)["total"]["ours"] != 43035


@pytest.fixture(scope="module")
def committed_tables():
    """The committed pattern tables, each read once (a 4096-configuration table takes seconds)."""
    stems = ("bisection-1x1x1", "bisection-1x2x4", "bisection-1x1.4142x1.4142", "bisection-1xsqrt2xsqrt2")
    return {stem: load(ROOT / "patterns" / f"{stem}.yaml") for stem in stems}


def test_committed_catalogue_and_patterns_validate(committed_tables):
    catalogue = load_catalogue(catalogue_path())
    check_catalogue(catalogue, "catalogue")
    ids = [t["id"] for t in catalogue["types"]]
    names = {t["name"] for t in catalogue["types"]}
    assert {"tetrahedron", "cuboid", "rectangular pyramid", "Tetrahedron Complement", "Generic #8"} <= names
    for stem, table in committed_tables.items():
        assert table.header["catalogue_version"] == catalogue["version"]
        assert len(table.configurations) == 4096
        known = set(ids)
        assert all(e["type"] in known for entry in table.configurations.values() for e in entry["optimal"])
        check_patterns(table, catalogue, stem)  # known types, node counts, and every configuration tiles the box


def test_pattern_lookup_equals_tessellate(committed_tables):
    table = committed_tables["bisection-1x2x4"]
    for code in bisection_codes()[::97]:
        tess = tessellate(Configuration.from_code(code, ("1", "2", "4")))
        assert table.elements(code) == [
            {"type": e.type.id, "nodes": list(e.nodes), "circumcenter": list(tess.circumcenter(e))}
            for e in tess.elements
        ]
        assert table.configurations[code]["fvm_adequate"] == tess.fvm_adequate


@pytest.fixture(scope="module")
def small_table(tmp_path_factory):
    path = tmp_path_factory.mktemp("small") / "small.yaml"
    study = run_study("bisection", Box.parse(("1", "2", "4")), ["000000000000", "800000000000", "880000000000"])
    write_patterns(study, path, "000000000000")
    return load_yaml(path)


@pytest.mark.parametrize(
    "edit, needle",
    [
        (lambda d: d.update(schema_version=7), "schema_version"),
        (lambda d: d["configurations"].update({"xyz": d["configurations"]["000000000000"]}), "configurations"),
        (lambda d: d["configurations"]["800000000000"]["optimal"][0].update(nodes=[1, 2]), "nodes"),
        (lambda d: d["configurations"]["800000000000"]["optimal"][0].pop("type"), "type"),
        (lambda d: d.pop("box"), "box"),
    ],
)
def test_broken_pattern_tables_are_refused(tmp_path, small_table, edit, needle):
    data = copy.deepcopy(small_table)
    edit(data)
    path = tmp_path / "broken.yaml"
    dump_yaml(data, path)
    with pytest.raises(FormatError, match=needle):
        load(path)


def test_reproduce_regenerates_committed_files_byte_for_byte(tmp_path):
    result = subprocess.run([sys.executable, "-m", "cospherical", "reproduce", "--root", str(tmp_path)],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    for folder in ("catalogue", "patterns", "results"):
        # results/sweep/, results/intersection/ and results/mesh/ come from other commands (README), not from reproduce
        committed = sorted(p.relative_to(ROOT) for p in (ROOT / folder).rglob("*") if p.is_file()
                           and not {"sweep", "intersection", "mesh"} & set(p.relative_to(ROOT).parts))
        assert committed == sorted(p.relative_to(tmp_path) for p in (tmp_path / folder).rglob("*") if p.is_file())
        for name in committed:
            if name.suffix == ".png":  # pictures depend on the matplotlib build; check they are pictures
                assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
                continue
            assert filecmp.cmp(ROOT / name, tmp_path / name, shallow=False), str(name)


def test_study_cli_json_shape(tmp_path):
    result = subprocess.run(
        [sys.executable, "-m", "cospherical", "study", "bisection", "--box", "1", "2", "4", "--format", "json",
         "--out", str(tmp_path), "--compare-paper"],
        capture_output=True, text=True,
    )
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    assert data["study"] == "bisection" and data["box"] == ["1", "2", "4"] and data["configurations"] == 4096
    assert data["face_points"] == "octree"
    optimal = data["criteria"]["optimal"]
    assert optimal["total"] == 45581 == sum(t["count"] for t in optimal["types"].values())
    assert data["fvm_adequate"] >= data["fvm_adequate_open"]
    assert data["paper"]["fvm_adequate"]["paper"] == 132
    stem = pattern_name("bisection", ("1", "2", "4"))
    assert json.loads((tmp_path / f"{stem}.json").read_text())["criteria"] == data["criteria"]
    assert len(load(tmp_path / f"{stem}.yaml").configurations) == 4096
