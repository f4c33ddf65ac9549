"""The catalogue's names: one rule, unique names, the paper's class as alias; the catalogue read fast and alike."""

from __future__ import annotations

import random
from dataclasses import replace

import pytest
import yaml

from cospherical import Configuration, tessellate
from cospherical.catalogue import Catalogue
from cospherical.catalogue.names import (catalogue_from_text, catalogue_path, known_name, load_catalogue,
                                         shipped_catalogue, type_name, type_names)
from cospherical.errors import FormatError
from cospherical.paper import paper_class


@pytest.fixture(scope="module")
def types():
    """The element types of 60 seeded bisection configurations in the cube and in the 1 x 2 x 4 box."""
    rng = random.Random(5)
    codes = ["".join(rng.choice("08") for _ in range(12)) for _ in range(60)]
    found = {}
    for box in (["1", "1", "1"], ["1", "2", "4"]):
        for code in codes:
            for element in tessellate(Configuration.from_code(code, box)).elements:
                found[element.type.id] = element.type
    assert len(found) > 12
    return found


def test_names_follow_the_rule_and_are_unique(types):
    # Another type without a class: a decagon-ended prism's counts are no class of the paper's.
    odd = replace(types["v8f6-c3cb81"], id="v20f12-000000", code="x", name="20-Vertex Polyhedron", structural=None,
                  vertices=20, edges=30, faces=12, face_kinds=(("decagon", 2), ("rectangle", 10)))
    names = type_names([*types.values(), odd])
    assert len({name for name, _ in names.values()}) == len(names) == len(types) + 1
    assert names[odd.id] == ("20-Vertex Polyhedron (10 rectangles + 2 decagons)", [])
    by_base: dict[str, list[str]] = {}
    for type_id, t in types.items():
        cls = paper_class(t)
        name, aliases = names[type_id]
        assert aliases == ([cls["name"]] if cls else [])
        base = t.structural or (cls["name"] if cls and not cls.get("structural") else None)
        assert base is not None and name.startswith(base)
        by_base.setdefault(base, []).append(type_id)
    for base, ids in by_base.items():  # variants numbered in the order of their ids, only where a name is shared
        expected = [base] if len(ids) == 1 else [f"{base} (variant {i + 1})" for i in range(len(ids))]
        assert [names[i][0] for i in sorted(ids)] == expected
    assert any(len(ids) > 1 for ids in by_base.values())  # the sample has a shared name


def test_a_catalogue_names_the_codes_it_has_and_nothing_else(types):
    t, cuboid = types["v4f4-8f0284"], types["v8f6-c3cb81"]
    data = shipped_catalogue().to_dict()
    data["types"] = [{**entry, "name": "My Tetrahedron"} if entry["code"] == t.code else entry
                     for entry in data["types"] if entry["code"] != cuboid.code]
    mine = Catalogue.from_dict(data)
    assert known_name(t.code, mine) == type_name(t, mine) == "My Tetrahedron"
    assert known_name(cuboid.code, mine) is None and type_name(cuboid, mine) == cuboid.name == "Cuboid"
    assert type_name(t) == known_name(t.code) == "Tetrahedron"  # the shipped catalogue's
    assert known_name(cuboid.code) == "Cuboid"


def test_the_shipped_catalogue_is_read_once_and_names_each_code_once():
    catalogue = shipped_catalogue()
    assert shipped_catalogue() is catalogue and catalogue_path().name == "catalogue.yaml"
    codes = [t.code for t in catalogue]
    names = [t.name for t in catalogue]
    assert len(set(codes)) == len(codes) == len(catalogue) and len(set(names)) == len(names)
    assert catalogue.schema_version == 1


@pytest.mark.oracle_pyyaml
def test_the_fast_reader_reads_what_a_yaml_reader_reads():
    # One JSON line per type is decoded as JSON; PyYAML reads the same file, and the same data spelt in block style.
    text = catalogue_path().read_text()
    data = load_catalogue(catalogue_path()).to_dict()
    assert yaml.load(text, Loader=yaml.CSafeLoader) == data  # libyaml: 20 times faster than PyYAML's own reader
    few = {**data, "types": data["types"][::10]}
    block = yaml.dump(few, Dumper=yaml.CSafeDumper, default_flow_style=False)
    assert "- {" not in block and catalogue_from_text(block, "block.yaml").to_dict() == few


@pytest.mark.parametrize("edit, needle", [
    (lambda text: text.replace('"vertices": 4,', '"vertices": "four",', 1), "catalogue format: at types.0.vertices"),
    (lambda text: text.replace("schema_version: 1", "schema_version: 2"), "catalogue format: at schema_version"),
    (lambda text: text.replace('{"id"', '{"id": 1, "id"', 1), "repeated key 'id'"),
    (lambda text: text + "- [\n", "bad.yaml"),
])
def test_a_bad_catalogue_is_one_line_naming_the_place(edit, needle):
    text = edit(catalogue_path().read_text())
    with pytest.raises(FormatError, match=needle) as error:
        catalogue_from_text(text, "bad.yaml")
    assert str(error.value).startswith("bad.yaml") and "\n" not in str(error.value)
