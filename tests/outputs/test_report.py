"""Text reports of study summaries: the frequency table, another study beside it, the paper's figures beside ours."""

from __future__ import annotations

import pytest

from cospherical import Box
from cospherical.outputs.report import comparison_lines, paper_set_gaps, study_comparison_lines, text_report
from cospherical.paper import paper_class, paper_studies
from cospherical.studies.engine import bisection_codes, run_study
from cospherical.studies.summary import compared_with, study_summary


@pytest.fixture(scope="module")
def tetrahedron():
    """The corner tetrahedron's 64 bisection configurations in the cube, every criterion."""
    study = run_study("bisection", Box.parse(["1", "1", "1"]), bisection_codes("tetrahedron"), element="tetrahedron")
    return study, study_summary(study)


def _paper_as_ours(fvm: int = 4096) -> dict:
    """A summary whose figures are the paper's own for box A (one type per class, counted as the paper counts)."""
    published = paper_studies()["bisection_A"]
    criteria = {}
    for criterion in ("optimal", "internal_faces", "internal_edges_and_faces"):
        counts = published[criterion]["counts"]
        types = {f"type-{i}": {"name": f"type {i}", "paper_class": name, "count": n, "share": 0.0, "configurations": 1}
                 for i, (name, n) in enumerate(counts.items())}
        criteria[criterion] = {"total": sum(counts.values()), "types_count": len(types), "types": types}
    return {"study": "bisection", "box": ["1", "1", "1"], "face_points": "octree", "configurations": 4096,
            "orbits": 1, "fvm_adequate": fvm, "fvm_adequate_open": 0, "criteria": criteria}


def test_the_papers_own_figures_differ_nowhere_and_one_change_is_marked():
    lines = comparison_lines(_paper_as_ours())
    assert lines[0].startswith("Beside the paper (bisection_A, box 1 x 1 x 1)")
    assert not [line for line in lines if "<- differs" in line]
    assert any("FVM adequate configurations: paper 4096, ours 4096" in line for line in lines)
    changed = _paper_as_ours(fvm=4000)
    changed["criteria"]["optimal"]["types"]["type-0"]["count"] += 1
    changed["criteria"]["optimal"]["total"] += 1
    marked = [line.split()[0] for line in comparison_lines(changed) if "<- differs" in line]
    assert marked == ["Cuboid", "total", "FVM"]  # the row, the total, the FVM count; nothing else


def test_a_study_the_paper_has_not(tetrahedron):
    study, summary = tetrahedron
    assert comparison_lines(summary, study) == ["The paper has no study of this box to compare with."]
    assert text_report(summary, compare_paper=True).endswith("The paper has no study of this box to compare with.\n")


def test_the_frequency_table_of_every_criterion(tetrahedron):
    study, summary = tetrahedron
    lines = text_report(summary).splitlines()
    assert lines[0] == (f"bisection study of the tetrahedron, box 1 x 1 x 1, face points octree: 64 configurations "
                        f"({study.orbits} orbits)")
    assert lines[1] == f"FVM adequate: {study.fvm_adequate} (closed tetrahedron), {study.fvm_adequate_open} (open tetrahedron)"
    for criterion, data in summary["criteria"].items():
        start = lines.index(next(line for line in lines if line.startswith(f"{criterion}: ")))
        assert lines[start] .startswith(f"{criterion}: {data['total']} elements, {data['types_count']} element types")
        rows = lines[start + 2:start + 2 + data["types_count"]]
        assert [row.split()[0] for row in rows] == list(data["types"])
        assert [int(row.split()[-3]) for row in rows] == [t["count"] for t in data["types"].values()]


def test_a_long_name_widens_its_column_and_is_never_cut(tetrahedron):
    _, summary = tetrahedron
    types = summary["criteria"]["optimal"]["types"]
    long = "A" * 70
    first = next(iter(types))
    edited = {**summary, "criteria": {"optimal": {**summary["criteria"]["optimal"],
                                                  "types": {**types, first: {**types[first], "name": long}}}}}
    rows = [line for line in text_report(edited).splitlines() if line.startswith("  v")]
    assert long in rows[0] and len(rows) == len(types)
    assert len({row.rindex("%") for row in rows}) == 1  # the share column at one place in every row


def test_another_study_beside_every_type_of_both(tetrahedron):
    _, summary = tetrahedron
    other = {**summary, "study": "leaves", "face_points": "explicit"}
    other = {**other, "criteria": {"optimal": {**summary["criteria"]["optimal"], "total": 1,
                                               "types": {"v9f9-000000": {"name": "Other", "count": 1}}}}}
    lines = study_comparison_lines(compared_with(summary, other))
    assert lines[0] == "Beside the leaves study with the explicit point policy, same box:"
    ids = [*summary["criteria"]["optimal"]["types"], "v9f9-000000"]
    rows = [line for line in lines if line.strip().startswith("v")]
    optimal = rows[:len(ids)]
    assert [row.split()[0] for row in optimal] == ids
    assert optimal[-1].split()[-2:] == ["0", "1"]  # a type of the other study only: none here


def test_only_elements_outside_the_papers_kept_classes_are_gaps():
    # 32 configurations, and two whose bipyramid and Generic #5 the paper's kept classes cannot split
    codes = bisection_codes()[:32] + ["888008008800", "088808808800"]
    study = run_study("bisection", Box.parse(["1", "1", "1"]), codes)
    found = 0
    for criterion in ("internal_faces", "internal_edges_and_faces"):
        kept = set(paper_studies()["bisection_A"][criterion]["counts"])
        gaps = paper_set_gaps(study, "bisection_A", criterion)
        found += len(gaps)
        assert [g["type"] for g in gaps] == sorted(g["type"] for g in gaps)
        for gap in gaps:
            element = next(e for t in study.tessellations.values() for e in t.elements if e.type.id == gap["type"])
            assert (paper_class(element.type) or {}).get("name") not in kept  # the element itself is no split
            assert 0 < gap["configurations"] <= len(codes) and gap["splits"]
    assert found
