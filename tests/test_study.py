"""Studies: symmetry, the paper's tables, catalogue and pattern tables."""

from __future__ import annotations

import copy
import filecmp
import hashlib
import json
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

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


# That the study's tessellations, mapped through the symmetries, equal direct ones is
# checked for every bisection configuration of four boxes and both point policies in
# test_delaunay_oracle, where the direct tessellations are made anyway.


def test_symmetry_maps_configurations_and_points():
    box = Box.parse(("1", "1", "1"))
    cfg = Configuration.from_steiner(box, {0: "1/4", 9: "3/16", 4: "1/4", 2: "1/4", 6: "1/4"})
    for sym in box_symmetries(box):
        image = sym.configuration(cfg)
        assert image.code == sym.code(cfg.code)
        nodes, image_nodes = cfg.nodes(), image.nodes()
        assert {sym.node_map[i]: sym.point(p) for i, p in nodes.items()} == image_nodes


@pytest.mark.parametrize("lengths", [("1", "1", "1"), ("1", "2", "2"), ("1", "2", "4")])
def test_orbit_representatives_without_numpy_equal_numpy_ones(lengths):
    # The pure-Python backend (one orbit at a time, no numpy) against the numpy backend:
    # the same representatives and the same (first) symmetries.
    import random

    import numpy as np

    from cospherical.core import symmetry
    from cospherical.studies.leaves import leaf_codes

    symmetries = box_symmetries(Box.parse(lengths))
    group = symmetry._group(symmetries)
    assert group is not None and symmetry._group(symmetries[:5]) is None  # not a group: the numpy path
    rng = random.Random(15)
    scattered = ["".join(rng.choice("0123456789abcdefABCDEF") for _ in range(12)) for _ in range(500)]
    scattered += [code + rng.choice(["+f", "+f0", "+f13", "+fb", "+f245b", "+f012345"]) for code in scattered[:200]]
    for codes in (bisection_codes(), leaf_codes(), scattered):
        masks = [symmetry._point_mask(code) if "+" in code else 0 for code in codes]
        numpy_keys = symmetry.orbit_point_keys(symmetry.code_digits(codes), np.array(masks, dtype=np.int64),
                                               symmetries, backend="numpy")
        assert symmetry._orbit_keys_python(codes, masks, group) == tuple(a.tolist() for a in numpy_keys)


def test_a_bisection_study_loads_no_numpy():
    # numpy takes a tenth of a second to import: the bisection study and its command do without it.
    script = ("import sys; from cospherical.cli import main; main(['study', 'bisection', '--format', 'json']); "
              "sys.exit('numpy' in sys.modules)")
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr


@pytest.mark.parametrize("key", ["bisection_A", "bisection_B", "bisection_C"])
def test_paper_optimal_tables_row_by_row(paper_studies, key):
    study = paper_studies[key.removeprefix("bisection_")]  # the session's studies (conftest.py)
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
    assert {"Tetrahedron", "Cuboid", "Rectangular Pyramid", "Tetrahedron Complement", "Generic #8"} <= names
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


# sha256 over every (code, criterion, elements) of each committed table, computed from the
# tables as written before entries became one JSON flow line each (block YAML read by PyYAML):
# the faster format must answer every lookup exactly as the previous one did.
PREVIOUS_FORMAT_DIGESTS = {
    "bisection-1x1x1": "42b2edc898170d41fa79d45812157cb8ea4836392fe3799854d3ff63a3923c0e",
    "bisection-1x2x4": "b8c9b8dee07d0d4019be053006e5d97302dade33555eb9e173b42617791e6d7f",
    "bisection-1x1.4142x1.4142": "7ca90c9a2bf73d9b1f792fb0fdfd9502b2a6d3ae11d75e5dfaf7801ff7317951",
    "bisection-1xsqrt2xsqrt2": "c56408071132f626ddfcb9f66b256e3b14b4ce291667a06dc1d73f605b6113e8",
    "leaves-1x1x1": "71f152faf11e4bd613ee7aaf9206c310a6e56166e192f6bdd4d854804a5af472",
    "leaves-1x2x4": "09d91f2c18a5ae7663ef40d9d35175350f5464a4d6dbd885de47f06848fb4295",
    "bisection-prism-1x1x1": "0ab5163f1d62c8474d53d88c805381c58aa25f40ff76caab6fcfa9139737b813",
    "bisection-pyramid-1x1x1": "96140b99fffe7f30f1b51af52fa92625914043278f3168af5d12ebb70dbf99ae",
    "bisection-tetrahedron-1x1x1": "945f8791d8f545eac0ff3771b757d5b17ae7497db171fa8bffdf6dd6a34dfbcd",
}


def test_committed_tables_answer_as_the_previous_format(committed_tables):
    tables = {**committed_tables, **{stem: load(ROOT / "patterns" / f"{stem}.yaml")
                                     for stem in PREVIOUS_FORMAT_DIGESTS if stem not in committed_tables}}
    assert sorted(tables) == sorted(p.stem for p in (ROOT / "patterns").glob("*.yaml"))
    for stem, table in tables.items():
        digest = hashlib.sha256()
        for code in table.configurations:
            for criterion in table.header["criteria"]:
                digest.update(json.dumps([code, criterion, table.elements(code, criterion)]).encode())
        assert digest.hexdigest() == PREVIOUS_FORMAT_DIGESTS[stem], stem


@pytest.mark.oracle_pyyaml
def test_a_standard_yaml_reader_reads_the_committed_files_alike(committed_tables):
    # PyYAML on a whole table takes ~15 s: read every 64th entry line with it, and the catalogue whole.
    for stem, table in committed_tables.items():
        lines = (ROOT / "patterns" / f"{stem}.yaml").read_text().split("\n")
        start = lines.index("configurations:") + 1
        sample = yaml.safe_load("\n".join(lines[:start] + lines[start:-1:64]))
        assert {k: v for k, v in sample.items() if k != "configurations"} == table.header
        assert len(sample["configurations"]) == 64
        for code, entry in sample["configurations"].items():
            assert entry == table.configurations[code]
    assert yaml.safe_load(catalogue_path().read_text()) == load_catalogue(catalogue_path())


@pytest.mark.parametrize("edit, needle", [
    (lambda line: line.replace("0.5", "5e-1", 1), "not a YAML 1.1 float"),
    (lambda line: line.replace('"fvm_adequate": true', '"fvm_adequate": true, "fvm_adequate": true'), "repeated key"),
    (lambda line: line.replace('"type": "v', '"type": "x', 1), "type"),
    (lambda line: line.replace('"nodes": [', '"nodes": [,', 1), "configurations/800000000000"),
])
def test_a_broken_entry_is_refused_when_read(tmp_path, small_table_path, edit, needle):
    lines = small_table_path.read_text().split("\n")
    at = next(i for i, line in enumerate(lines) if line.startswith("  '800000000000'"))
    lines[at] = edit(lines[at])
    path = tmp_path / "broken.yaml"
    path.write_text("\n".join(lines))
    table = load(path)  # only the header is read here
    assert table.elements("000000000000")
    with pytest.raises(FormatError, match=needle):
        table.elements("800000000000")
    result = subprocess.run([sys.executable, "-m", "cospherical", "check", str(path)], capture_output=True, text=True)
    assert result.returncode == 2 and len(result.stderr.strip().splitlines()) == 1 and needle in result.stderr


@pytest.fixture(scope="module")
def small_table_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("small") / "small.yaml"
    study = run_study("bisection", Box.parse(("1", "2", "4")), ["000000000000", "800000000000", "880000000000"])
    write_patterns(study, path, "000000000000")
    return path


@pytest.fixture(scope="module")
def small_table(small_table_path):
    return load_yaml(small_table_path)


@pytest.mark.parametrize(
    "edit, needle",
    [
        (lambda d: d.update(schema_version=7), "schema_version"),
        (lambda d: d["configurations"].update({"xyz": copy.deepcopy(d["configurations"]["000000000000"])}),
         "configurations"),  # a copy: a shared object is written as a YAML alias, refused as such
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


def test_reproduce_regenerates_committed_files_byte_for_byte(tmp_path, monkeypatch, capsys):
    # From nothing, in one run, whatever state the catalogue is in: here the catalogue the
    # package would read is corrupt, and the root holds stale, half-written and corrupt outputs.
    import cospherical.catalogue.store as store
    from cospherical.cli import main

    corrupt = tmp_path / "corrupt-catalogue.yaml"
    corrupt.write_text("types: [unclosed\n")
    monkeypatch.setattr(store, "catalogue_path", lambda: corrupt)
    store.shipped_catalogue.cache_clear()
    store._shipped_names.cache_clear()
    root = tmp_path / "root"
    (root / "catalogue").mkdir(parents=True)
    (root / "catalogue" / "catalogue.yaml").write_text("types: [unclosed\n")
    (root / "results").mkdir()
    (root / "results" / "summary.md").write_text("stale")
    (root / "results" / ".summary.md.abcd1234.tmp").write_text("left by a killed run")
    try:
        assert main(["reproduce", "--root", str(root)]) == 0, capsys.readouterr().err
    finally:
        store.shipped_catalogue.cache_clear()
        store._shipped_names.cache_clear()
    tmp_path = root
    for folder in ("catalogue", "patterns", "results"):
        # results/sweep/, results/intersection/, results/mesh/ and results/benchmarks/ come from other
        # commands and the benchmark scripts (CONTRIBUTING.md), not from reproduce
        committed = sorted(p.relative_to(ROOT) for p in (ROOT / folder).rglob("*") if p.is_file()
                           and not {"sweep", "intersection", "mesh", "benchmarks"} & set(p.relative_to(ROOT).parts))
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
