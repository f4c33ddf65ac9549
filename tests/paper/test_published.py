"""The paper's classes, figures and notes as data: consistent in themselves and with the paper's printed values."""

from __future__ import annotations

import pytest

from cospherical import Configuration, tessellate
from cospherical.paper.published import paper_class, paper_classes, paper_notes, paper_studies

SIDES = {"triangle": 3, "rectangle": 4, "quadrilateral": 4, "pentagon": 5, "hexagon": 6}


def test_every_class_is_a_convex_polyhedron():
    # Euler (V - E + F = 2), every edge on two faces (sum of sides = 2E), the face kinds count F.
    names = [entry["name"] for entry in paper_classes()]
    assert len(names) == len(set(names)) == 24  # the 7 final elements and 17 new ones of bisection
    for entry in paper_classes():
        v, e, f = entry["counts"]
        assert v - e + f == 2, entry["name"]
        for kinds in entry["face_kinds"]:
            assert sum(kinds.values()) == f and sum(SIDES[k] * n for k, n in kinds.items()) == 2 * e, entry["name"]


def test_the_printed_totals():
    # The paper's Table 2 totals (spec/paper-tables.yaml) and its claimed intersection count; each table's
    # rows add up to its total.
    studies = paper_studies()
    assert {key: study["optimal"]["total"] for key, study in studies.items()} == {
        "bisection_A": 37259, "bisection_B": 45581, "bisection_C": 43035, "intersection_cube": 46491970}
    assert studies["bisection_B"]["fvm_adequate_configurations"] == 132
    for key, study in studies.items():
        for criterion in ("optimal", "internal_faces", "internal_edges_and_faces"):
            if criterion in study:
                assert sum(study[criterion]["counts"].values()) == study[criterion]["total"], (key, criterion)
                if key.startswith("bisection"):  # the intersection's new classes have no face kinds in the paper
                    assert set(study[criterion]["counts"]) <= {c["name"] for c in paper_classes()}


def test_notes_are_sentences():
    notes = paper_notes()
    assert {"fvm", "exact_sqrt2", "none_policy"} <= set(notes)
    assert all(text.strip().endswith(".") and "\n" not in text for text in notes.values())


@pytest.mark.parametrize("code, name", [
    ("000000000000", "Cuboid"),                 # the empty box
    ("800000000000", "Quadrilateral Pyramid"),  # one point splits the box into pyramids and tetrahedra
])
def test_the_class_of_an_element_type_has_its_counts_and_face_kinds(code, name):
    types = {e.type for e in tessellate(Configuration.from_code(code)).elements}
    classes = {t: paper_class(t) for t in types}
    assert name in {c["name"] for c in classes.values() if c}
    for t, entry in classes.items():
        assert entry is not None
        assert list(entry["counts"]) == [t.vertices, t.edges, t.faces] and dict(t.face_kinds) in entry["face_kinds"]


def test_a_type_of_no_class_has_none():
    # A pentagonal prism (10 vertices) is no class of the paper's.
    from cospherical.core.element_types import ElementType

    known = tessellate(Configuration.from_code("000000000000")).elements[0].type
    fields = {name: getattr(known, name) for name in ElementType.__dataclass_fields__}
    fake = ElementType(**{**fields, "vertices": 10, "edges": 15, "faces": 7,
                          "face_kinds": (("pentagon", 2), ("rectangle", 5))})
    assert paper_class(fake) is None
