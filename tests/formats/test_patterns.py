"""Pattern tables: the committed ones validate and answer as before; broken ones are refused."""

from __future__ import annotations

import copy
import hashlib
import json
from pathlib import Path

import pytest
import yaml
from commands import in_process, one_clean_line
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from sampling import examples, sampled_table

from cospherical import Box, Configuration, standard_shape, tessellate
from cospherical.catalogue import catalogue_path, load_catalogue, shipped_catalogue
from cospherical.errors import FormatError
from cospherical.files.yamlio import dump_yaml, load_yaml
from cospherical.formats.check import check_catalogue, check_patterns
from cospherical.formats.patterns import entry_elements, load, pattern_name, write_patterns
from cospherical.studies.engine import bisection_codes, run_study
from cospherical.studies.leaves import leaf_codes
from tests.core.test_shapes import SHAPES

CUBE = ("1", "1", "1")
ROOT = Path(__file__).resolve().parents[2]
PATTERNS = ROOT / "patterns"


@pytest.fixture(scope="module")
def committed_tables():
    """The committed pattern tables, each read once (a 4096-configuration table takes seconds)."""
    stems = ("bisection-1x1x1", "bisection-1x2x4", "bisection-1x1.4142x1.4142", "bisection-1xsqrt2xsqrt2")
    return {stem: load(ROOT / "patterns" / f"{stem}.yaml") for stem in stems}


def test_committed_catalogue_and_patterns_validate(committed_tables, full, tmp_path):
    catalogue = load_catalogue(catalogue_path())
    check_catalogue(catalogue, "catalogue")
    names = {t.name for t in catalogue}
    assert {"Tetrahedron", "Cuboid", "Rectangular Pyramid", "Tetrahedron Complement", "Generic #8"} <= names
    for stem, table in committed_tables.items():
        assert table.header["catalogue_version"] == catalogue.version
        assert len(table.configurations) == 4096
        # every element's type is the catalogue's, in every entry of every committed table: checked as
        # test_committed_tables_answer_as_the_previous_format reads them all (once, not twice)
        # the deep check (known types, node counts, every configuration tiles the box, types and
        # circumcenters recomputed): about 3 CPU-s a table, so by default every type of the table and a
        # seeded 1 in 8 of the other entries (sampling.py), all with --full. reproduce regenerates these
        # files byte for byte (outputs/test_reproduce.py).
        if not full:
            table = load(sampled_table(ROOT / "patterns" / f"{stem}.yaml", tmp_path / f"{stem}.yaml", 1 / 8, seed=4096))
        check_patterns(table, catalogue, stem)


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
    known = {t.id for t in load_catalogue(catalogue_path())}
    for stem, table in tables.items():
        digest = hashlib.sha256()
        for code, entry in table.configurations.items():  # every entry read and validated, a chunk at a time
            # json.dumps([code, criterion, elements]) written in its parts (the same text: "[a, b, c]"), each
            # list of elements encoded and checked once per entry (a criterion that names another shares its list)
            texts: dict[int, str] = {}
            for criterion in table.header["criteria"]:
                elements = entry_elements(entry, criterion)
                text = texts.get(id(elements))
                if text is None:
                    assert all(element["type"] in known for element in elements), (stem, code, criterion)
                    text = texts[id(elements)] = json.dumps(elements)
                digest.update(f"[{json.dumps(code)}, {json.dumps(criterion)}, {text}]".encode())
        assert digest.hexdigest() == PREVIOUS_FORMAT_DIGESTS[stem], stem


@pytest.mark.oracle_pyyaml
def test_a_standard_yaml_reader_reads_the_committed_files_alike(committed_tables):
    # PyYAML on a whole table takes ~15 s: read every 64th entry line with it (the catalogue: tests/catalogue/test_names.py).
    for stem, table in committed_tables.items():
        lines = (ROOT / "patterns" / f"{stem}.yaml").read_text().split("\n")
        start = lines.index("configurations:") + 1
        sample = yaml.safe_load("\n".join(lines[:start] + lines[start:-1:64]))
        assert {k: v for k, v in sample.items() if k != "configurations"} == table.header
        assert len(sample["configurations"]) == 64
        for code, entry in sample["configurations"].items():
            assert entry == table.configurations[code]


@pytest.mark.parametrize("edit, needle", [
    (lambda line: line.replace("0.5", "5e-1", 1), "not a YAML 1.1 float"),
    (lambda line: line.replace('"fvm_adequate": true', '"fvm_adequate": true, "fvm_adequate": true'), "repeated key"),
    (lambda line: line.replace('"type": "v', '"type": "x', 1), "type"),
    (lambda line: line.replace('"nodes": [', '"nodes": [,', 1), "configurations/800000000000"),
])
def test_a_broken_entry_is_refused_when_read(tmp_path, capsys, small_table_path, edit, needle):
    lines = small_table_path.read_text().split("\n")
    at = next(i for i, line in enumerate(lines) if line.startswith("  '800000000000'"))
    lines[at] = edit(lines[at])
    path = tmp_path / "broken.yaml"
    path.write_text("\n".join(lines))
    table = load(path)  # only the header is read here
    assert table.elements("000000000000")
    with pytest.raises(FormatError, match=needle):
        table.elements("800000000000")
    result = in_process(capsys, "check", path)  # the command's code here: a process added 0.4 CPU-s a case
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


def test_leaf_tables_pass_check_and_look_up_by_whole_point_set_code(tmp_path, capsys):
    # The committed tables are regenerated byte for byte (outputs/test_reproduce.py, cli/test_study.py); checking
    # them whole here would cost half a minute of YAML parsing, so a table of every 31st
    # leaf configuration of each box goes through the same `cospherical check`.
    sample = leaf_codes()[::31]
    paths = []
    for box in (CUBE, ("1", "2", "4")):
        study = run_study("leaves", Box.parse(box), sample, "explicit")
        paths.append(tmp_path / f"{pattern_name('leaves', box, 'explicit')}.yaml")
        write_patterns(study, paths[-1], shipped_catalogue().version)
    result = in_process(capsys, "check", catalogue_path(), *paths)
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


def test_elements_of_a_code_not_held_is_a_key_error():
    from cospherical.formats.patterns import load

    table = load(PATTERNS / "bisection-1x1x1.yaml")
    for code in (["x"], None, 7, "zzz"):
        with pytest.raises(KeyError):
            table.elements(code)


@pytest.mark.parametrize("name", SHAPES)
def test_committed_shape_tables_pass_check(name):
    from cospherical import load_catalogue
    from cospherical.catalogue import catalogue_path
    from cospherical.formats.check import check_patterns
    from cospherical.formats.patterns import load

    table = load(ROOT / "patterns" / f"bisection-{name}-1x1x1.yaml")
    shape = standard_shape(name)
    assert table.header["element"] == name and len(table.configurations) == 1 << len(shape.edges)
    check_patterns(table, load_catalogue(catalogue_path()), name)  # known types, node counts, tiling
    for code in list(table.configurations)[::5]:
        tess = tessellate(Configuration.from_code(code, shape=shape))
        assert table.elements(code) == [
            {"type": e.type.id, "nodes": list(e.nodes), "circumcenter": list(tess.circumcenter(e)),
             **({"mirror": True} if e.mirrored else {})} for e in tess.elements]
        assert table.configurations[code]["fvm_adequate"] == tess.fvm_adequate


ELEMENT_VALUES = st.one_of(st.none(), st.booleans(), st.integers(-1, 28), st.floats(), st.text(max_size=3),
                           st.sampled_from(["v4f4-8f0284", "v4f4-8f0284\n", "optimal", "internal_faces", 1.0]))


@st.composite
def _mutated_entries(draw):
    """An entry of the committed cube table, with a few of its values, keys or lists changed."""
    entry = copy.deepcopy(draw(st.sampled_from(_SOME_ENTRIES)))
    for _ in range(draw(st.integers(0, 3))):
        criterion = draw(st.sampled_from(sorted(entry)))
        elements = entry[criterion]
        if not (isinstance(elements, list) and elements and all(isinstance(e, dict) for e in elements)) \
                or draw(st.booleans()):
            entry[criterion] = draw(st.one_of(ELEMENT_VALUES, st.lists(ELEMENT_VALUES, max_size=2)))
            continue
        element = draw(st.sampled_from(elements))
        field = draw(st.sampled_from(["type", "nodes", "circumcenter", "mirror", "other"]))
        if field == "nodes" and draw(st.booleans()):
            # a list among the ids too: it cannot go into a set (the plain rules check types first)
            element["nodes"] = draw(st.lists(st.one_of(ELEMENT_VALUES, st.lists(st.integers(0, 26), max_size=1)),
                                             max_size=28))
        else:
            element[field] = draw(st.one_of(ELEMENT_VALUES, st.lists(ELEMENT_VALUES, max_size=4)))
    return entry


_CUBE_TABLE = load(PATTERNS / "bisection-1x1x1.yaml")
_SOME_ENTRIES = [_CUBE_TABLE.configurations[code] for code in ("000000000000", "800000000000", "888888888888",
                                                                "808080808080")]


@settings(max_examples=examples(800), deadline=None, suppress_health_check=list(HealthCheck))
@given(_mutated_entries(), st.sampled_from(["800000000000", "8000000000000", "80000000000g", "888888888888+f01"]))
def test_the_plain_entry_rules_accept_only_what_the_schema_accepts(entry, code):
    # formats/patterns.py checks entries by hand where it can, and leaves the rest to the schema's
    # validator: what it accepts, the schema must accept too (the schema's verdict is the only one)
    from cospherical.files.yamlio import validate
    from cospherical.formats.patterns import _plainly_valid

    data = {**_CUBE_TABLE.header, "configurations": {code: entry}}
    if _plainly_valid(data, "t.yaml"):
        validate(data, "patterns", "t.yaml")


def test_a_list_among_the_node_ids_is_refused_in_one_line(tmp_path, capsys, small_table_path):
    # was a TypeError (unhashable list) from the plain entry rules: now the schema's refusal, as for any bad id
    lines = small_table_path.read_text().split("\n")
    at = next(i for i, line in enumerate(lines) if line.startswith("  '800000000000'"))
    lines[at] = lines[at].replace('"nodes": [', '"nodes": [[0], ', 1)
    path = tmp_path / "nested.yaml"
    path.write_text("\n".join(lines))
    with pytest.raises(FormatError, match=r"800000000000\.optimal\.0\.nodes\.0: value must be integer"):
        load(path).elements("800000000000")
    one_clean_line(in_process(capsys, "check", path), "nested.yaml")
