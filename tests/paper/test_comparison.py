"""Our tables beside the paper's, row by row."""

from __future__ import annotations

import pytest

from cospherical import Box
from cospherical.paper import paper_comparison, paper_study_key
from cospherical.studies.engine import bisection_codes, run_study
from cospherical.studies.summary import study_summary


def test_paper_table_r2_row_by_row(paper_studies):
    table = paper_comparison(study_summary(paper_studies["C"]), "bisection_C", "internal_faces")
    assert all(row["paper"] == row["ours"] for row in table["rows"]), table["rows"]
    assert table["total"] == {"paper": 43231, "ours": 43231}


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
