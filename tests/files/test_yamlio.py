"""YAML and JSON in, as every reader of the package takes them: safe, bounded, one-line errors."""

from __future__ import annotations

import json
import math
import os

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from cospherical.errors import FormatError
from cospherical.files.yamlio import (MAX_INTEGER_DIGITS, check_nesting, dump_yaml, load_yaml, parse_json, parse_yaml,
                                      read_text, validate, yaml_float)


def one_line(error: pytest.ExceptionInfo) -> str:
    text = str(error.value)
    assert "\n" not in text and "Traceback" not in text
    return text


@pytest.mark.oracle_pyyaml
@given(st.floats(allow_nan=False, allow_infinity=False))
def test_a_float_reads_back_as_the_same_float(x):
    # PyYAML (YAML 1.1) reads 1e-05 as a string: the text must carry a dot before the exponent.
    back = yaml.safe_load(yaml_float(x))
    assert isinstance(back, float) and back == x and math.copysign(1, back) == math.copysign(1, x)


@pytest.mark.oracle_pyyaml
@given(st.recursive(st.none() | st.booleans() | st.integers(-10**9, 10**9) | st.text(max_size=8),
                    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner, max_size=4),
                    max_leaves=12))
@settings(max_examples=40)
def test_what_is_written_reads_back_the_same(tmp_path_factory, data):
    path = tmp_path_factory.getbasetemp() / "written.yaml"  # one file, written over by each example
    dump_yaml(data, path)
    assert load_yaml(path) == data == yaml.safe_load(path.read_text())


@pytest.mark.parametrize("text, needle", [
    ("a: 1\nb: 2\na: 3\n", "line 3: repeated key 'a'"),
    ("a: &x [1, 2]\nb: *x\n", "a YAML alias"),
    ("a: !!python/object:os.system {}\n", "demo.yaml: line 1"),
    ("a: [1, 2\n", "demo.yaml: line 2"),
    ("[" * 65 + "]" * 65, "nested too deeply"),
    ("{[1]: 2}\n", "not a plain value"),
    ("a: " + "9" * 5000 + "\n", "demo.yaml: an integer of more than 4,300 digits"),  # not Python's advice
])
def test_hostile_yaml_is_one_line_naming_the_file(text, needle):
    with pytest.raises(FormatError) as error:
        parse_yaml(text, "demo.yaml")
    assert needle in one_line(error) and one_line(error).startswith("demo.yaml")


def test_a_date_stays_a_string_and_json_is_read_as_json():
    assert parse_yaml("when: 2001-13-14\nday: 2001-12-14\n", "d.yaml") == {"when": "2001-13-14", "day": "2001-12-14"}
    # YAML 1.1 reads 4e-06 as a string; a summary written as JSON keeps its numbers
    assert parse_yaml('{"share": 4e-06}', "s.json") == {"share": 4e-06}
    assert yaml.safe_load('{"share": 4e-06}') == {"share": "4e-06"}


def test_nesting_is_bounded_by_brackets_and_by_indentation():
    check_nesting("[" * 64 + "]" * 64, "ok")
    check_nesting("a:\n" + " " * 256 + "b: 1\n", "ok")
    for text in ("{" * 65, "a:\n" + " " * 257 + "b: 1\n", "- " * 129 + "x\n"):
        with pytest.raises(FormatError, match="nested too deeply"):
            check_nesting(text, "deep.yaml")


def test_json_refuses_repeated_keys_and_long_numbers():
    assert parse_json('{"n": ' + "9" * MAX_INTEGER_DIGITS + "}", "n.json") == {"n": int("9" * MAX_INTEGER_DIGITS)}
    for text, needle in (('{"a": 1, "a": 2}', "repeated key 'a'"),
                         ('{"n": ' + "9" * (MAX_INTEGER_DIGITS + 1) + "}", f"{MAX_INTEGER_DIGITS + 1} digits"),
                         ('{"a": }', "n.json: line 1: not valid JSON")):
        with pytest.raises(FormatError) as error:
            parse_json(text, "n.json")
        assert needle in one_line(error)
    assert parse_json('{"n": ' + "9" * 60 + "}", "n.json", max_digits=60)["n"] == 10**60 - 1


def test_only_a_regular_file_within_the_bound_is_read(tmp_path):
    path = tmp_path / "a.yaml"
    path.write_text("été\n")
    assert read_text(path) == "été\n" and read_text(path, max_bytes=len("été\n".encode())) == "été\n"
    os.mkfifo(tmp_path / "fifo")  # a FIFO without a writer would block an open() that waits for one
    (tmp_path / "latin1").write_bytes(b"caf\xe9")
    for target, needle in ((path, "too large (6 bytes; at most 5)"), (tmp_path, "a folder"),
                           (tmp_path / "fifo", "a special file"), (tmp_path / "missing", "No such file"),
                           (tmp_path / "latin1", "cannot read")):
        with pytest.raises(FormatError) as error:
            read_text(target, max_bytes=5)
        assert needle in one_line(error) and str(target) in one_line(error)


def test_validation_names_the_file_the_schema_and_the_place():
    validate({"schema_version": 1, "version": "0123456789ab", "types": []}, "catalogue", "c.yaml")
    with pytest.raises(FormatError) as error:
        validate({"schema_version": 1, "version": "0123456789ab", "types": [{"id": 3}]}, "catalogue", "c.yaml")
    assert one_line(error).startswith("c.yaml: catalogue format: at types.0")


def test_a_compiled_validator_is_kept_and_gives_fastjsonschemas_verdicts(tmp_path, monkeypatch):
    import sys

    import fastjsonschema

    from cospherical.files.yamlio import _compiled_validator

    schema = {"type": "object", "properties": {"n": {"type": "integer", "minimum": 2}}, "required": ["n"]}
    text = json.dumps(schema)
    fresh = fastjsonschema.compile(schema)
    monkeypatch.setattr(sys, "dont_write_bytecode", True)  # PYTHONDONTWRITEBYTECODE: nothing kept
    assert _compiled_validator("demo", text, tmp_path)({"n": 2}) == {"n": 2} and not any(tmp_path.iterdir())
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    first = _compiled_validator("demo", text, tmp_path)
    kept = list(tmp_path.glob("demo.*.marshal"))
    assert len(kept) == 1  # kept for the next process
    second = _compiled_validator("demo", text, tmp_path)  # read back, not compiled
    for check in (fresh, first, second):
        assert check({"n": 3}) == {"n": 3}
        with pytest.raises(fastjsonschema.JsonSchemaValueException, match="data.n must be bigger than or equal to 2"):
            check({"n": 1})
    kept[0].write_bytes(b"\x00damaged")  # a damaged file is compiled again and replaced
    assert _compiled_validator("demo", text, tmp_path)({"n": 2}) == {"n": 2}
    assert kept[0].read_bytes() != b"\x00damaged"
    other = json.dumps({**schema, "required": []})  # another text of the schema: its own file, the old one dropped
    assert _compiled_validator("demo", other, tmp_path)({}) == {}
    assert [p.name for p in tmp_path.glob("demo.*.marshal")] != [kept[0].name]
    assert len(list(tmp_path.glob("demo.*"))) == 1
    (tmp_path / "file").write_text("")  # a folder it cannot make (root writes anywhere else): compiled, no error
    assert _compiled_validator("demo", text, tmp_path / "file" / "cache")({"n": 2}) == {"n": 2}


def test_validated_data_is_kept_and_read_back_only_for_the_same_text(tmp_path, monkeypatch):
    """The shipped catalogue's parsed, validated data kept: read back for the same text, never for another."""
    import sys

    from cospherical.catalogue.names import _catalogue_data, catalogue_path
    from cospherical.files.yamlio import read_text, validated_data

    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    parsed = []

    def parse(text, name):
        parsed.append(name)
        return _catalogue_data(text, name)

    text = read_text(catalogue_path())
    first = validated_data(text, "catalogue", "c.yaml", parse, tmp_path)
    assert first == validated_data(text, "catalogue", "c.yaml", parse, tmp_path) and parsed == ["c.yaml"]
    assert len(list(tmp_path.glob("catalogue-data.*.marshal"))) == 1
    broken = text.replace("schema_version: 1", "schema_version: one", 1)  # another text: parsed and validated
    with pytest.raises(FormatError, match="catalogue format"):
        validated_data(broken, "catalogue", "c.yaml", parse, tmp_path)
    assert len(parsed) == 2
    next(tmp_path.glob("catalogue-data.*.marshal")).write_bytes(b"\x00damaged")  # parsed again
    assert validated_data(text, "catalogue", "c.yaml", parse, tmp_path) == first and len(parsed) == 3
