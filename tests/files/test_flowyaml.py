"""Pattern tables in our one-line-per-entry form: read by splitting lines, any other form told apart at once."""

from __future__ import annotations

from pathlib import Path

import json

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from cospherical.errors import FormatError
from cospherical.files.flowyaml import decode_entry, flow

PATTERNS = Path(__file__).resolve().parents[2] / "patterns"


def test_a_table_not_in_our_line_form_is_told_apart_without_cutting_it_into_lines():
    # the one-line-per-entry reader gives up at the first line of another form, before it makes the
    # lines (20 MB of block style made 132 MB of them; a 100 MB file took 0.83 GB to be refused)
    import tracemalloc

    from cospherical.files.flowyaml import split_section

    row = "  - type: v8f6-c3cb81\n    nodes:\n    - 0\n    - 1\n"
    text = "schema_version: 1\nconfigurations:\n  '000000000000':\n    optimal:\n" + row * (20_000_000 // len(row))
    tracemalloc.start()
    try:
        assert split_section(text, "configurations") is None
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 1 << 20, peak
    ours = (PATTERNS / "bisection-tetrahedron-1x1x1.yaml").read_text()
    header, entries = split_section(ours, "configurations")  # our own form still takes the fast path
    assert entries and "configurations" not in header


@pytest.mark.parametrize("colon", [":", " :", " : ", "\t:\n", "\r\n:  "])
def test_a_repeated_key_is_refused_however_its_colon_is_spaced(colon):
    # one key spaced otherwise and one the usual way: as many '": ' as keys kept
    text = '{"b": {"c"' + colon + '2, "c": 3}}'
    with pytest.raises(FormatError, match="e.json: repeated key 'c'"):
        decode_entry(text, "e.json")
    assert decode_entry(text.replace('"c": 3', '"d": 3'), "e.json") == {"b": {"c": 2, "d": 3}}


def _values(text):
    leaves = st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False, allow_infinity=False) | text
    return st.recursive(leaves, lambda inner: st.lists(inner, max_size=4) | st.dictionaries(text, inner, max_size=4),
                        max_leaves=12)


@settings(max_examples=60, deadline=None)
@given(_values(st.text(max_size=6)))
def test_a_flow_value_is_json_of_the_same_value(value):
    # the exact-type shortcuts (node-id lists, strings) write what the general path does: booleans
    # in a list of integers stay booleans, any text is escaped as json.dumps escapes it
    assert json.loads(flow(value)) == value
    assert flow(value) == flow(json.loads(json.dumps(value)))  # tuples and lists alike


@settings(max_examples=60, deadline=None)
@given(_values(st.text(st.characters(min_codepoint=0x20, max_codepoint=0x7E), max_size=6)))
def test_a_flow_value_is_read_back_by_a_yaml_1_1_reader(value):
    # PyYAML (YAML 1.1, not ours) reads the line as the same value: floats with a dot before the exponent
    assert yaml.safe_load(flow(value)) == value


@pytest.mark.parametrize("text", ["1e5", " 1.0e5", '{"a": 1e5}', '{"a":\t-2E+1}', "[0.5, 1e-1]", "[1.5e3,2]",
                                  '{"a": [0.5,\n 3e0]}'])
def test_a_float_that_yaml_1_1_reads_otherwise_is_refused_wherever_it_stands(text):
    with pytest.raises(FormatError, match="not a YAML 1.1 float"):
        decode_entry(text, "e.json")


def test_exponent_like_text_inside_strings_is_only_text():
    # type ids are hex ("3e..."): decoded alike whichever float parser reads the numbers
    assert decode_entry('{"type": "v4f4-3e05", "c": [0.5, 1.0e-05], "k: 1e5": 2}', "e.json") == \
        {"type": "v4f4-3e05", "c": [0.5, 1e-05], "k: 1e5": 2}
