"""The intersection family (paper, section 5): enumeration, orbits, runs, resumption."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from sampling import sampled_table

from cospherical import Box
from cospherical.studies.engine import bisection_codes
from cospherical.choices import INSERTION_ORDERS
from cospherical.studies.intersection import intersection_codes, run_intersection, set_patterns
from cospherical.studies.summary import study_summary


@pytest.mark.parametrize("order", INSERTION_ORDERS)
def test_enumeration_counts(order):
    # which edges of a set of four carry a point, and their order with ties: 150 per set
    assert [len(set_patterns(r, order)) for r in (2, 4, 8, 16)] == [16, 66, 126, 150]
    assert len(intersection_codes(16, order)) == 150**3 == 3_375_000 != 187**3 + 1
    assert all(d % (16 // 4) == 0 for p in set_patterns(4, order) for d in p)


def test_insertion_orders_differ_and_follow_the_midpoint_scheme():
    edge, rank, reverse = (set(set_patterns(16, o)) for o in INSERTION_ORDERS)
    assert edge != rank != reverse
    # two levels on edges 0 and 1: the first inserted goes to 1/2, the other halfway to an end
    assert (8, 12, 0, 0) in rank and (4, 8, 0, 0) in reverse
    assert (8, 12, 0, 0) in edge and (8, 4, 0, 0) in edge and (4, 8, 0, 0) not in edge


def test_resolution_2_is_the_bisection_study(paper_studies):
    # The compiled two-stage pipeline against the Python path (exact walk in Python
    # integers, Study, choose) on the 4096 bisection configurations, every criterion:
    # the cube's study is the session's (conftest.py).
    ours = run_intersection(2, jobs=1)
    codes = sorted("".join("%x" % d for d in row) for row in intersection_codes(2))
    assert codes == sorted(bisection_codes())
    bisection = study_summary(paper_studies["A"])
    assert paper_studies["A"].box.texts == ("1", "1", "1")
    assert ours["criteria"]["optimal"]["total"] == 37259
    for criterion, data in bisection["criteria"].items():
        mine = ours["criteria"][criterion]
        assert mine["total"] == data["total"] and mine.get("splits") == data.get("splits"), criterion
        assert {k: (v["count"], v["configurations"]) for k, v in mine["types"].items()} == \
               {k: (v["count"], v["configurations"]) for k, v in data["types"].items()}, criterion
    assert (ours["fvm_adequate"], ours["fvm_adequate_open"]) == (bisection["fvm_adequate"], bisection["fvm_adequate_open"])


@pytest.fixture(scope="module")
def pool_run():
    return run_intersection(4, jobs=2)


def test_process_pool_dask_and_brute_force_agree(pool_run, full, monkeypatch):
    dask = run_intersection(4, dask_workers=2)
    assert pool_run["configurations"] == 66**3 and pool_run["orbits"] == 32077
    assert dask == pool_run
    assert set(pool_run["criteria"]) == {"optimal", "internal_faces", "internal_edges_and_faces"}
    # Every configuration tessellated against one per orbit counted as many times as its orbit
    # has members: the whole family with --full (its 287,496 configurations take 20 CPU-s), by
    # default a seeded 1 in 32 of the orbits, each with all its members (the statistics of a
    # set of whole orbits are the same either way).
    if full:
        brute, by_orbits = run_intersection(4, jobs=2, brute_force=True), pool_run
    else:
        brute, by_orbits = _sampled_orbits_both_ways(monkeypatch)
    assert brute["orbits"] == brute["configurations"] == by_orbits["configurations"]
    assert {**brute, "orbits": by_orbits["orbits"]} == by_orbits


def _sampled_orbits_both_ways(monkeypatch):
    """The R = 4 study on a seeded sample of whole orbits: brute force, and one per orbit."""
    import cospherical.studies.intersection.run as run
    from cospherical.core.symmetry import box_symmetries, orbit_keys
    from cospherical.studies.intersection import orbits

    digits = intersection_codes(4)
    keys, _ = orbit_keys(digits, box_symmetries(Box.parse(["1", "1", "1"])), "compiled")  # each code's orbit
    codes = (digits.astype(np.int64) << (4 * np.arange(11, -1, -1))).sum(axis=1)
    reps, sizes, _ = orbits(4)
    pick = np.sort(np.random.default_rng(4).choice(len(reps), len(reps) // 32, replace=False))
    members = np.sort(codes[np.isin(keys, reps[pick])])
    assert len(members) == sizes[pick].sum() > len(pick)
    monkeypatch.setattr(run, "orbits", lambda resolution, order: (reps[pick], sizes[pick], len(members)))
    monkeypatch.setattr(run, "all_configurations", lambda resolution, order: members)
    return run_intersection(4, brute_force=True), run_intersection(4)  # in this process: the pool ran above


def test_compiled_stage_agrees_with_the_python_walk_on_a_sample():
    # Stage 1 (the compiled kernel on many codes) against tessellate() with the Python walk.
    from cospherical import Configuration
    from cospherical.core.delaunay import delaunay_cells
    from cospherical.core.geometry import Frame
    from cospherical.core.polyhedron import polyhedron
    from cospherical.core.symmetry import key_code
    from cospherical.studies.intersection import all_configurations, tessellate_chunk

    codes = all_configurations(16)
    sample = np.sort(codes[np.random.default_rng(16).choice(len(codes), 300, replace=False)])
    cells = tessellate_chunk(sample)
    for i, code in enumerate(sample.tolist()):
        cfg = Configuration.from_code(key_code(code))
        frame = Frame.build(cfg.nodes(), cfg.box.squared)
        python = [polyhedron(frame, cell) for cell in delaunay_cells(frame, backend="python")]
        assert cells["tets"][i] == sum(len(p.nodes) == 4 for p in python)
        assert cells["polys"][i] == sum(len(p.nodes) > 4 for p in python)
        assert cells["closed"][i] == all(p.center_in_box(closed=True) for p in python)
        assert cells["open"][i] == all(p.center_in_box(closed=False) for p in python)
    offsets = np.concatenate([[0], np.cumsum(cells["polys"])])
    i = int(np.argmax(cells["polys"]))
    cfg = Configuration.from_code(key_code(int(sample[i])))
    frame = Frame.build(cfg.nodes(), cfg.box.squared)
    masks = {sum(1 << n for n in cell.nodes) for cell in delaunay_cells(frame, backend="python") if len(cell.nodes) > 4}
    assert set(cells["poly_mask"][offsets[i]:offsets[i + 1]].tolist()) == masks


def test_the_paper_figures_beside_ours(pool_run):
    from cospherical.paper import paper_comparison, paper_study_key

    key, notes = paper_study_key(pool_run)
    assert key == "intersection_cube" and "insertion_order" in notes
    table = paper_comparison(pool_run, key)
    assert table["total"] == {"paper": 46491970, "ours": pool_run["criteria"]["optimal"]["total"]}


def test_an_interrupted_run_resumes_to_the_same_result(tmp_path):
    args = [sys.executable, "-m", "cospherical", "study", "intersection", "--resolution", "2", "--jobs", "2",
            "--chunk-size", "16", "--out", str(tmp_path), "--resume", "--format", "json"]
    full = json.loads(subprocess.run(args, capture_output=True, text=True, check=True).stdout)
    assert full["criteria"]["optimal"]["total"] == 37259
    chunks = sorted((tmp_path / "checkpoints").glob("*-cells-*.npz"))
    assert len(chunks) > 3 and list((tmp_path / "checkpoints").glob("*-elements-*.json"))
    for chunk in chunks[::2] + sorted((tmp_path / "checkpoints").glob("*-elements-*.json"))[:1]:
        chunk.unlink()  # as if the run had stopped before these
    resumed = json.loads(subprocess.run(args, capture_output=True, text=True, check=True).stdout)
    assert resumed == full


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
    # every criterion's elements tile the cube exactly (the deep check), in either form
    assert main(["check", str(path)]) == 0 and main(["check", str(store)]) == 0
    # the same bytes, however the work was cut and run
    again = tmp_path / "again"
    again.mkdir()
    write_pattern_table(TableRun(summary, jobs=1, chunk=1000), shipped_catalogue().version,
                        yaml_path=again / path.name, store=again / store.name)
    assert (again / path.name).read_bytes() == path.read_bytes()
    assert (again / store.name).read_bytes() == store.read_bytes()


def test_table_lines_joined_from_cells_are_those_of_each_tessellation(pool_run):
    # The table is joined from each distinct cell's text; the same lines, byte for byte,
    # come from tessellating every configuration and splitting it under each kept set.
    from cospherical import Configuration, tessellate
    from cospherical.catalogue import split_tessellation
    from cospherical.core.symmetry import key_code
    from cospherical.files.flowyaml import mapping_text
    from cospherical.studies.intersection.table import cell_texts, distinct_cells, table_entries
    from cospherical.formats.patterns import configuration_line
    from cospherical.studies.intersection import orbits

    kept = {c: data["kept"] for c, data in pool_run["criteria"].items() if c != "optimal"}
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


def test_rank_and_reverse_are_mirror_families():
    # t -> 1 - t turns the scheme inserting from the lowest level into the one inserting
    # from the highest: the two families are reflections, so their statistics agree.
    reflected = {tuple(16 - d if d else 0 for d in p) for p in set_patterns(16, "rank")}
    assert reflected == set(set_patterns(16, "reverse"))
    a, b = run_intersection(4, "rank"), run_intersection(4, "reverse")  # in this process: no pool to start
    assert a["criteria"] == b["criteria"] and a["orbits"] == b["orbits"]


@pytest.fixture(scope="module")
def r4_table(pool_run, tmp_path_factory):
    """The R = 4 pattern table, as YAML and as an indexed store."""
    from cospherical.catalogue import shipped_catalogue
    from cospherical.formats.intersection_table import write_pattern_table
    from cospherical.studies.intersection.table import TableRun

    folder = tmp_path_factory.mktemp("r4")
    write_pattern_table(TableRun(pool_run, jobs=2), shipped_catalogue().version, yaml_path=folder / "r4.yaml",
                        store=folder / "r4.sqlite")
    return folder / "r4.yaml", folder / "r4.sqlite"


def test_a_pattern_table_at_resolution_4_passes_check(r4_table, full, tmp_path):
    # Every type of the intersection studies is in the shipped catalogue, so `check`
    # (known types, node counts, exact tiling, recomputed types and circumcenters) passes their
    # tables. All 32,077 entries take 30 CPU-s (--full); by default a sample (sampling.py) with
    # every type of the table and a seeded 1 in 8 of the other entries. The R = 2 table is
    # checked whole, as YAML and as a store, in test_pattern_table_of_the_representatives.
    from cospherical.cli import main

    path = r4_table[0] if full else sampled_table(r4_table[0], tmp_path / "sample.yaml", 1 / 8, seed=4)
    assert main(["check", str(path)]) == 0


def test_the_indexed_store_answers_exactly_like_the_yaml(r4_table):
    from cospherical.cli import main
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
    assert main(["diff", *map(str, r4_table)]) == 0
