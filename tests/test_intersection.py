"""The intersection family (paper, section 5): enumeration, orbits, runs, resumption."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from cospherical import Box
from cospherical.intersection import INSERTION_ORDERS, intersection_codes, run_intersection, set_patterns
from cospherical.report import study_summary
from cospherical.study import bisection_codes, run_study


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


def test_resolution_2_is_the_bisection_study():
    ours = run_intersection(2, jobs=1)
    codes = sorted("".join("%x" % d for d in row) for row in intersection_codes(2))
    assert codes == sorted(bisection_codes())
    bisection = study_summary(run_study("bisection", Box.parse(("1", "1", "1")), bisection_codes(),
                                        criteria=("optimal",)))
    assert ours["criteria"]["optimal"]["total"] == bisection["criteria"]["optimal"]["total"] == 37259
    assert {k: v["count"] for k, v in ours["criteria"]["optimal"]["types"].items()} == \
           {k: v["count"] for k, v in bisection["criteria"]["optimal"]["types"].items()}
    assert ours["fvm_adequate"] == bisection["fvm_adequate"]


def test_process_pool_equals_one_process_and_brute_force_on_a_sample():
    one = run_intersection(4, jobs=1)
    two = run_intersection(4, jobs=2)
    assert one == two
    assert one["configurations"] == 66**3 and one["orbits"] < one["configurations"]
    # brute force (no orbits) on a sample: each sampled configuration's own tessellation
    from cospherical import Configuration, tessellate
    from cospherical.intersection import orbits
    from cospherical.symmetry import box_symmetries, key_code, orbit_keys

    digits = intersection_codes(4)
    sample = digits[np.random.default_rng(1).choice(len(digits), 150, replace=False)]
    keys, sym_index = orbit_keys(sample, box_symmetries(Box.parse(("1", "1", "1"))))
    symmetries = box_symmetries(Box.parse(("1", "1", "1")))
    for row, key, index in zip(sample, keys.tolist(), sym_index.tolist()):
        code = "".join("%x" % d for d in row)
        direct = tessellate(Configuration.from_code(code))
        rep = tessellate(Configuration.from_code(key_code(key)))
        assert symmetries[index].code(code) == key_code(key)
        assert sorted(e.type.id for e in direct.elements) == sorted(e.type.id for e in rep.elements)
        assert direct.fvm_adequate == rep.fvm_adequate
    reps, sizes, total = orbits(4)
    assert sizes.sum() == total == 66**3


def test_an_interrupted_run_resumes_to_the_same_result(tmp_path):
    args = [sys.executable, "-m", "cospherical", "study", "intersection", "--resolution", "2", "--jobs", "2",
            "--chunk-size", "16", "--out", str(tmp_path), "--resume", "--format", "json"]
    full = json.loads(subprocess.run(args, capture_output=True, text=True, check=True).stdout)
    assert full["criteria"]["optimal"]["total"] == 37259
    chunks = sorted((tmp_path / "checkpoints").glob("*.json"))
    assert len(chunks) > 3
    for chunk in chunks[::2]:  # as if the run had stopped before these
        chunk.unlink()
    resumed = json.loads(subprocess.run(args, capture_output=True, text=True, check=True).stdout)
    assert resumed == full
