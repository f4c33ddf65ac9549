"""The intersection study's pattern table written: YAML and indexed store from the same lines, the same bytes
however the work is cut."""

from __future__ import annotations

import json
import zlib

import pytest
import yaml

from cospherical.formats.intersection_table import entry_chunk
from cospherical.formats.sqlite_store import dictionary_of
from cospherical.studies.intersection import run_intersection

ENTRIES = [("000000000000", json.dumps({"fvm_adequate": True, "optimal": [{"type": "v8f6-c3cb81", "nodes": [0, 1]}]})),
           ("800000000000", json.dumps({"fvm_adequate": False, "optimal": []}))]


@pytest.mark.oracle_pyyaml
def test_a_chunk_as_yaml_lines_and_as_store_rows():
    text, rows = entry_chunk(ENTRIES, True, None)
    assert rows == [] and yaml.safe_load("configurations:\n" + text)["configurations"] == \
        {code: json.loads(entry) for code, entry in ENTRIES}
    dictionary = dictionary_of([entry for _, entry in ENTRIES])
    text, rows = entry_chunk(ENTRIES, False, dictionary)
    assert text == "" and [code for code, _ in rows] == [code for code, _ in ENTRIES]
    for (_, packed), (_, entry) in zip(rows, ENTRIES):  # zlib with the table's preset dictionary undoes it
        unpacker = zlib.decompressobj(zdict=dictionary)
        assert (unpacker.decompress(packed) + unpacker.flush()).decode() == entry


def test_pattern_table_of_the_representatives(tmp_path):
    from cospherical import Configuration, tessellate
    from cospherical.catalogue import shipped_catalogue
    from cospherical.cli import main
    from cospherical.core.symmetry import key_code
    from cospherical.formats.intersection_table import write_pattern_table
    from cospherical.studies.intersection.table import TableRun
    from cospherical.formats.patterns import load
    from cospherical.studies.intersection import orbits

    summary = run_intersection(2, jobs=1)
    path, store = tmp_path / "patterns.yaml", tmp_path / "patterns.sqlite"
    write_pattern_table(TableRun(summary, jobs=2, chunk=40), shipped_catalogue().version, yaml_path=path, store=store)
    table = load(path)
    reps, _, _ = orbits(2)
    assert sorted(table.configurations) == [key_code(k) for k in reps.tolist()]
    assert "smallest" in table.header["symmetry"] and table.header["criteria"][0] == "optimal"
    for code in sorted(table.configurations)[::7]:
        direct = tessellate(Configuration.from_code(code))
        assert [(e["type"], e["nodes"]) for e in table.elements(code)] == \
               [(e.type.id, list(e.nodes)) for e in direct.elements]
    # every criterion's elements tile the cube exactly (the deep check), in either form; diff finds them the same
    assert main(["check", str(path)]) == 0 and main(["check", str(store)]) == 0
    assert main(["diff", str(path), str(store)]) == 0
    # the same bytes, however the work was cut and run
    again = tmp_path / "again"
    again.mkdir()
    write_pattern_table(TableRun(summary, jobs=1, chunk=1000), shipped_catalogue().version,
                        yaml_path=again / path.name, store=again / store.name)
    assert (again / path.name).read_bytes() == path.read_bytes()
    assert (again / store.name).read_bytes() == store.read_bytes()
