"""Study summaries: the frequency tables of a study, recounted configuration by configuration."""

from __future__ import annotations

from collections import Counter

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cospherical import Box
from cospherical.catalogue import split_tessellation
from cospherical.core.base_element import base_element
from cospherical.studies.engine import bisection_codes, run_study
from cospherical.studies.summary import TypeInfo, compared_with, frequency_table, study_summary

BOX = Box.parse(["1", "1", "1"])


@pytest.fixture(scope="module")
def study():
    """The corner tetrahedron's 64 bisection configurations in the cube: tessellated once per orbit of its 6 symmetries."""
    return run_study("bisection", BOX, bisection_codes("tetrahedron"), element="tetrahedron")


def test_the_summary_is_the_count_of_every_configuration_tessellated(study):
    # Brute force beside the study's orbits: each configuration tessellated and split on its own.
    summary = study_summary(study)
    element = base_element("tetrahedron", BOX)
    tessellations = [element.tessellate(element.configuration(code)) for code in bisection_codes("tetrahedron")]
    assert (summary["configurations"], summary["element"], summary["box"]) == (64, "tetrahedron", ["1", "1", "1"])
    assert summary["orbits"] == study.orbits < 64
    assert summary["fvm_adequate"] == sum(t.fvm_adequate for t in tessellations)
    assert summary["fvm_adequate_open"] == sum(t.fvm_adequate_open for t in tessellations)
    for criterion, data in summary["criteria"].items():
        kept = frozenset(study.choices[criterion].kept) if criterion != "optimal" else frozenset()
        split = [split_tessellation(t, kept, criterion)[0] for t in tessellations]
        counts = Counter(e.type.id for t in split for e in t.elements)
        configurations = Counter(type_id for t in split for type_id in {e.type.id for e in t.elements})
        assert {i: (row["count"], row["configurations"]) for i, row in data["types"].items()} == \
               {i: (counts[i], configurations[i]) for i in counts}, criterion
        assert data["total"] == sum(counts.values())


@given(st.dictionaries(st.sampled_from(["v4f4-a", "v5f5-b", "v6f5-c", "v8f6-d"]), st.integers(1, 10**6), min_size=1))
@settings(max_examples=40)
def test_a_frequency_table_adds_up_and_orders_by_count(counts):
    classes = {"v4f4-a": "Tetrahedron", "v5f5-b": None, "v6f5-c": "Tetrahedron", "v8f6-d": None}
    types = {i: TypeInfo(f"name {i}", classes[i], 4, 6, 4) for i in counts}
    table = frequency_table(counts, dict.fromkeys(counts, 1), types, {})
    rows = table["types"]
    assert table["total"] == sum(counts.values()) and table["types_count"] == len(counts) and "splits" not in table
    assert list(rows) == sorted(counts, key=lambda i: (-counts[i], i))
    assert sum(row["share"] for row in rows.values()) == pytest.approx(1, abs=len(rows) * 5e-7)
    # a type without a paper class counts as a class of its own
    assert table["paper_classes_count"] == len({classes[i] or i for i in counts})


def test_splits_are_listed_per_type_by_their_pieces(study):
    table = frequency_table({"a": 2}, {"a": 1}, {"a": TypeInfo("A", None, 4, 6, 4)},
                            {"b": {("a", "a"): 3, ("a",): 1}})
    assert table["splits"] == {"b": [{"pieces": ["a"], "configurations": 1}, {"pieces": ["a", "a"], "configurations": 3}]}


def test_names_given_replace_the_catalogues(study):
    some = next(iter(study_summary(study)["criteria"]["optimal"]["types"]))
    renamed = study_summary(study, {some: ("My Name", [])})
    assert renamed["criteria"]["optimal"]["types"][some]["name"] == "My Name"
    assert TypeInfo.of(study.type_counts("optimal")[0].type, "X").name == "X"


def test_another_study_set_beside_keeps_its_figures_only(study):
    summary = study_summary(study)
    other = {**summary, "study": "leaves", "face_points": "explicit", "orbits": 1}
    both = compared_with(summary, other)
    assert {k: v for k, v in both.items() if k != "compared_with"} == summary
    beside = both["compared_with"]
    assert (beside["study"], beside["face_points"], beside["orbits"]) == ("leaves", "explicit", 1)
    for criterion, data in summary["criteria"].items():
        assert beside["criteria"][criterion]["total"] == data["total"]
        assert all(set(row) == {"name", "count"} for row in beside["criteria"][criterion]["types"].values())
