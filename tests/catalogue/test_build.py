"""The catalogue built from studies: every type once, examples that give their type, splits that fill their element."""

from __future__ import annotations

import json
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from cospherical import Box, tessellate
from cospherical.catalogue import shipped_catalogue
from cospherical.catalogue.build import build_catalogue, intersection_examples
from cospherical.core.base_element import base_element
from cospherical.errors import FormatError
from cospherical.files.data import data_path
from cospherical.files.yamlio import validate
from cospherical.studies.engine import bisection_codes, run_study

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def studies():
    """Two small studies: the tetrahedron's 64 configurations in the cube, 64 of the cuboid's in the 1 x 2 x 4 box."""
    return (run_study("bisection", Box.parse(["1", "1", "1"]), bisection_codes("tetrahedron"), element="tetrahedron"),
            run_study("bisection", Box.parse(["1", "2", "4"]), bisection_codes()[:64]))


@pytest.fixture(scope="module")
def catalogue(studies):
    """The catalogue built from them, as the document written to the file."""
    return build_catalogue(studies).to_dict()


def test_every_type_of_the_studies_once_in_a_valid_catalogue(studies, catalogue):
    validate(catalogue, "catalogue", "built")
    met = {e.type.id for study in studies for choice in study.choices.values()
           for tess in choice.tessellations.values() for e in tess.elements}
    ids = [t["id"] for t in catalogue["types"]]
    assert sorted(ids) == sorted(met)
    assert ids == [t["id"] for t in sorted(catalogue["types"], key=lambda t: (t["vertices"], t["faces"], t["id"]))]
    for study in studies:
        for criterion, choice in study.choices.items():
            if criterion != "optimal":
                assert set(choice.kept) <= set(catalogue["criteria"][criterion]["kept"]) <= set(ids)


def test_the_version_is_a_digest_of_the_content(studies, catalogue):
    assert build_catalogue(studies).to_dict() == catalogue  # deterministic
    assert build_catalogue(studies[:1]).version != catalogue["version"]
    assert len(catalogue["version"]) == 12 and int(catalogue["version"], 16) >= 0


def _exact(coordinates) -> list[tuple[Fraction, ...]]:
    return [tuple(Fraction(x) for x in point) for point in coordinates]  # dyadic floats: exact


def test_each_example_gives_its_type_and_its_faces(catalogue):
    for entry in catalogue["types"]:
        example = entry["example"]
        element = base_element(example.get("element", "cuboid"), Box.parse(example["box"]), example["face_points"])
        configuration = element.configuration(example["configuration"])
        elements = {e.nodes: e.type.id for e in tessellate(configuration).elements}
        assert elements[tuple(example["nodes"])] == entry["id"]  # a re-tessellation, from the code alone
        points = _exact(example["coordinates"])
        faces = entry["reference_faces"]
        assert len(faces) == entry["faces"] and sum(len(f["nodes"]) for f in faces) == 2 * entry["edges"]
        kinds: dict[str, int] = {}
        for face in faces:
            kinds[face["kind"]] = kinds.get(face["kind"], 0) + 1
            a, b, c = (points[i] for i in face["nodes"][:3])
            normal = np.cross(np.subtract(b, a), np.subtract(c, a))
            sides = {int(np.sign(np.dot(normal, np.subtract(p, a)))) for p in points}
            on_plane = {i for i, p in enumerate(points) if np.dot(normal, np.subtract(p, a)) == 0}
            assert on_plane == set(face["nodes"]) and len(sides - {0}) == 1, (entry["id"], face)  # a hull face
        assert kinds == entry["face_kinds"]


def test_each_split_fills_its_element_with_catalogued_pieces(catalogue):
    # The pieces' volumes (Qhull) add up to the element's, their vertices are the element's, their types catalogued.
    types = {t["id"]: t for t in catalogue["types"]}
    splits = 0
    for entry in catalogue["types"]:
        points = np.array(entry["example"]["coordinates"])
        whole = ConvexHull(points).volume
        for criterion, options in entry["splits"].items():
            for pieces in options:
                splits += 1
                assert all(len(p["nodes"]) == types[p["type"]]["vertices"] and set(p["nodes"]) <= set(range(len(points)))
                           for p in pieces)
                assert sum(ConvexHull(points[p["nodes"]]).volume for p in pieces) == pytest.approx(whole, rel=1e-12)
    assert splits > 3


def test_the_shipped_catalogue_holds_every_type_of_the_intersection_studies():
    known = {t.id for t in shipped_catalogue()}
    examples = {e["element"].type.id for e in intersection_examples()}
    assert examples <= known
    for summary in (ROOT / "results" / "intersection").glob("*/intersection-r16-*.json"):
        for criterion, data in json.loads(summary.read_text())["criteria"].items():
            assert set(data["types"]) <= examples, (summary.name, criterion)


def test_an_example_that_no_longer_gives_its_type_is_refused(tmp_path):
    text = data_path("intersection-examples.yaml").read_text()
    assert intersection_examples(tmp_path / "missing.yaml") == []
    broken = tmp_path / "examples.yaml"
    broken.write_text(text.replace('"type": "v5f5-45a4de"', '"type": "v5f5-000000"', 1))
    with pytest.raises(FormatError, match="types/1: the example gives type v5f5-45a4de, not v5f5-000000"):
        intersection_examples(broken)
    broken.write_text("types: {}\n")
    with pytest.raises(FormatError, match="not a list of examples"):
        intersection_examples(broken)
