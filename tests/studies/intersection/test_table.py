"""The intersection study's pattern table: its lines joined from distinct cells, checked, and read from either form."""

from __future__ import annotations

import re

import pytest



def test_table_lines_joined_from_cells_are_those_of_each_tessellation(r4_run):
    # The table is joined from each distinct cell's text; the same lines, byte for byte,
    # come from tessellating every configuration and splitting it under each kept set.
    from cospherical import Configuration, tessellate
    from cospherical.catalogue import split_tessellation
    from cospherical.core.symmetry import key_code
    from cospherical.files.flowyaml import mapping_text
    from cospherical.studies.intersection.table import cell_texts, distinct_cells, table_entries
    from cospherical.formats.patterns import configuration_line
    from cospherical.studies.intersection import orbits

    kept = {c: data["kept"] for c, data in r4_run["criteria"].items() if c != "optimal"}
    reps, _, _ = orbits(4)
    codes = reps[::40]
    cells = [tuple(row) for row in distinct_cells(codes).tolist()]
    texts = dict(zip([cell[:2] for cell in cells], cell_texts(cells, kept)))
    joined = "".join(mapping_text(code, entry) for code, entry in table_entries(codes, texts, ["optimal", *kept]))
    expected = []
    for code in map(key_code, codes.tolist()):
        tess = tessellate(Configuration.from_code(code))
        split = {c: split_tessellation(tess, frozenset(types), c)[0] for c, types in kept.items()}
        expected.append(configuration_line(code, tess.fvm_adequate, {"optimal": tess, **split}))
    assert joined == "".join(expected)
    assert any('"internal_faces": [' in line for line in expected)  # some configurations are split


def test_a_pattern_table_at_resolution_4_passes_check(r4_table, r4_run):
    # Every type of the intersection studies is in the shipped catalogue, so `check`
    # (known types, node counts, exact tiling, recomputed types and circumcenters) passes their
    # tables. All 32,077 entries take 30 CPU-s (--full); by default the table of a sample of them
    # (conftest.py) with every type of the whole table and a seeded 1 in 16 of the other entries. The
    # R = 2 table is checked whole, as YAML and as a store, in test_pattern_table_of_the_representatives.
    from cospherical.cli import main

    met = set(re.findall(r'"type": "([^"]+)"', r4_table[0].read_text()))
    assert met == {t for criterion in r4_run["criteria"].values() for t in criterion["types"]}
    assert main(["check", str(r4_table[0])]) == 0


def test_the_indexed_store_answers_exactly_like_the_yaml(r4_table):
    from cospherical.formats.patterns import load

    yaml_table, store = (load(path) for path in r4_table)
    assert store.header == yaml_table.header and list(store.configurations) == list(yaml_table.configurations)
    for code in yaml_table.configurations:
        assert store.configurations.text(code) == yaml_table.configurations.text(code)
    for code in list(yaml_table.configurations)[::10]:
        for criterion in yaml_table.header["criteria"]:
            assert store.elements(code, criterion) == yaml_table.elements(code, criterion)
    with pytest.raises(KeyError):
        store.elements("fffffffffff0")
    # `diff` reading a YAML table and its store alike: formats/test_intersection_table.py, at R = 2 (here every
    # entry's text is compared above; diff reading both R = 4 forms whole cost 1.6 CPU-s more)
