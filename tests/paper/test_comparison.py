"""Our tables beside the paper's, row by row."""

from __future__ import annotations

from cospherical.paper import paper_comparison
from cospherical.studies.summary import study_summary


def test_paper_table_r2_row_by_row(paper_studies):
    table = paper_comparison(study_summary(paper_studies["C"]), "bisection_C", "internal_faces")
    assert all(row["paper"] == row["ours"] for row in table["rows"]), table["rows"]
    assert table["total"] == {"paper": 43231, "ours": 43231}
