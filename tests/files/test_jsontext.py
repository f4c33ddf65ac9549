"""Results as text: the JSON people read is JSON, laid out one value per line, lists of numbers kept whole."""

from __future__ import annotations

import json

import yaml

from cospherical.files.jsontext import dump, to_json

DATA = {"study": "bisection", "box": ["1", "2", "4"], "counts": {"optimal": [3, 1, 4]},
        "rows": [{"class": "Cube", "paper": 1, "ours": None}], "empty": {}, "nested": [[1, 2], [3]]}


def test_json_for_people_reads_back_as_the_same_data():
    text = to_json(DATA)
    assert json.loads(text) == DATA
    lines = text.splitlines()
    assert '  "box": ["1", "2", "4"],' in lines and '    "optimal": [3, 1, 4]' in lines  # one line each
    assert all(len(line) - len(line.lstrip()) in (0, 2, 4, 6, 8) for line in lines)


def test_dump_writes_json_or_yaml_of_the_same_data():
    assert json.loads(dump(DATA, "json")) == DATA and dump(DATA, "json").endswith("}\n")
    assert yaml.safe_load(dump(DATA, "yaml")) == DATA
