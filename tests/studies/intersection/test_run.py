"""Running the intersection study: its two stages against the Python path, every backend alike, resumption."""

from __future__ import annotations

import json

import numpy as np
import pytest
from commands import in_process

from cospherical import Box
from cospherical.studies.engine import bisection_codes
from cospherical.studies.intersection import intersection_codes, run_intersection
from cospherical.studies.summary import study_summary


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


def test_process_pool_dask_and_brute_force_agree(r4_run, full, monkeypatch):
    assert r4_run["configurations"] == 66**3 and r4_run["orbits"] == 32077
    assert set(r4_run["criteria"]) == {"optimal", "internal_faces", "internal_edges_and_faces"}
    # A pool of two and a Dask cluster of two give one process's summary, on a run cut into many chunks
    # joined in whatever order they finish: R = 2 in 16 chunks of 40 orbits (R = 4's default chunks are
    # 7 of 5,000: the same joining, 10 CPU-s more), and R = 4 too with --full.
    one = run_intersection(2, chunk=40)
    assert run_intersection(2, jobs=2, chunk=40) == one
    assert run_intersection(2, dask_workers=2, chunk=40) == one
    if full:
        assert run_intersection(4, jobs=2) == r4_run and run_intersection(4, dask_workers=2) == r4_run
    # Every configuration tessellated against one per orbit counted as many times as its orbit
    # has members: the whole family with --full (its 287,496 configurations take 20 CPU-s), by
    # default a seeded 1 in 64 of the orbits (501 orbits, 4,386 configurations: 4 CPU-s brute force; 1 in 32: 6.6), each
    # with all its members (the statistics of a set of whole orbits are the same either way). The orbits'
    # members are held to Qhull member by member for the bisection family (core/test_delaunay.py).
    if full:
        brute, by_orbits = run_intersection(4, jobs=2, brute_force=True), r4_run
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
    pick = np.sort(np.random.default_rng(4).choice(len(reps), len(reps) // 64, replace=False))
    members = np.sort(codes[np.isin(keys, reps[pick])])
    assert len(members) == sizes[pick].sum() > len(pick)
    monkeypatch.setattr(run, "orbits", lambda resolution, order: (reps[pick], sizes[pick], len(members)))
    monkeypatch.setattr(run, "all_configurations", lambda resolution, order: members)
    return run_intersection(4, brute_force=True), run_intersection(4)  # in this process: the pool is held to it above


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


def test_the_paper_figures_beside_ours(r4_run):
    from cospherical.paper import paper_comparison, paper_study_key

    key, notes = paper_study_key(r4_run)
    assert key == "intersection_cube" and "insertion_order" in notes
    table = paper_comparison(r4_run, key)
    assert table["total"] == {"paper": 46491970, "ours": r4_run["criteria"]["optimal"]["total"]}


def test_an_interrupted_run_resumes_to_the_same_result(tmp_path, capsys):
    # the command's code in this process, one job: the checkpoints are read and written around whichever
    # backend runs the missing chunks (a pool's and Dask's chunks are held to one process's above; a run
    # stopped by a signal is test_hostile.py's and test_outputs.py's)
    args = ["study", "intersection", "--resolution", "2", "--jobs", "1", "--chunk-size", "16", "--out", tmp_path,
            "--resume", "--format", "json"]
    run = in_process(capsys, *args)
    assert run.returncode == 0, run.stderr
    full = json.loads(run.stdout)
    assert full["criteria"]["optimal"]["total"] == 37259
    chunks = sorted((tmp_path / "checkpoints").glob("*-cells-*.npz"))
    assert len(chunks) > 3 and list((tmp_path / "checkpoints").glob("*-elements-*.json"))
    for chunk in chunks[::2] + sorted((tmp_path / "checkpoints").glob("*-elements-*.json"))[:1]:
        chunk.unlink()  # as if the run had stopped before these
    run = in_process(capsys, *args)
    assert run.returncode == 0, run.stderr
    assert json.loads(run.stdout) == full


@pytest.mark.parametrize("code", ["0088c4044048", "8888a0000808", "4c0000c40000"])
def test_a_cell_named_by_its_node_mask_is_the_configurations_cell(code):
    # Stage 1 names a cell (node mask, configuration); the polyhedron rebuilt from that name is the cell the
    # Python walk finds in the whole configuration. A mask that is no cell of it is refused.
    from cospherical import Configuration
    from cospherical.core.delaunay import delaunay_cells
    from cospherical.core.geometry import Frame
    from cospherical.core.polyhedron import polyhedron
    from cospherical.studies.intersection.run import NotACell, cell_polyhedron

    configuration = Configuration.from_code(code)
    frame = Frame.build(configuration.nodes(), configuration.box.squared)
    cells = delaunay_cells(frame, backend="python")
    for cell in cells:
        points, poly = cell_polyhedron(sum(1 << n for n in cell.nodes), int(code, 16))
        expected = polyhedron(frame, cell)
        assert [n for n, _ in points] == list(cell.nodes)
        assert (poly.faces, poly.face_kinds, poly.unit_volume, poly.center) == \
               (expected.faces, expected.face_kinds, expected.unit_volume, expected.center)
    largest = max(cells, key=lambda c: len(c.nodes))
    neighbour = next(c for c in cells if c is not largest and set(c.nodes) & set(largest.nodes))
    assert 26 not in configuration.nodes()  # no body point: not every face is split
    for nodes in (set(largest.nodes) | set(neighbour.nodes),  # two cells together: not on one sphere
                  set(largest.nodes) - {largest.nodes[0]},    # part of a cell: its sphere has the rest on it
                  set(largest.nodes) | {26}):                 # a node the configuration lacks
        with pytest.raises(NotACell):
            cell_polyhedron(sum(1 << n for n in nodes), int(code, 16))
