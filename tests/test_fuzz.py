"""Fuzzing the readers and the command line: no input may fail with anything but the clean error.

Counts (max_examples): codes 2500, lengths 2500, Steiner maps 1500, number grammar 2000,
Steiner lists 1000, YAML documents 2000, command lines 2000: more than 13,000 generated inputs per run.
"""

from __future__ import annotations

import io
import re
from contextlib import redirect_stderr, redirect_stdout

import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cospherical import Configuration, InputError, Length
from cospherical.cli import main
from cospherical.core.exact import parse_rational
from cospherical.errors import FormatError
from cospherical.files.yamlio import parse_yaml
from cospherical.formats.check import check_catalogue, check_patterns, validated
from cospherical.formats.patterns import table_from_data


# The number grammar, written again here as the oracle: ASCII digits only, an optional sign, an
# integer or decimal with an optional exponent, or a fraction; at most 40 digits above and below.
ORACLE = re.compile(r"[+-]?([0-9]+(\.[0-9]+)?([eE][+-]?[0-9]+)?|[0-9]+/[0-9]+)")
# characters that look like digits, signs or spaces to a person but are not ASCII
LOOKALIKES = "\u0661\u0662\u0663\u06f1\u0967\uff10\uff11\uff12\u00b2\u2212\u00a0\u2009\uff0f\u2044_"


def fuzz(n: int):
    return settings(max_examples=n, deadline=None, suppress_health_check=list(HealthCheck))


HEX = "0123456789abcdefABCDEF"


@fuzz(2500)
@given(st.one_of(st.text(max_size=16), st.text(alphabet=HEX + "xg -", min_size=10, max_size=14)))
def test_configuration_codes(text):
    try:
        cfg = Configuration.from_code(text)
    except InputError as error:
        assert "configuration code" in str(error)
    else:
        assert cfg.code == text.lower()


@fuzz(2500)
@given(st.one_of(st.text(max_size=20),
                 st.from_regex(r"\A-?[0-9]{0,4}(\.[0-9]{0,4})?(/[0-9]{0,3})?\Z"),
                 st.from_regex(r"\A([0-9./]{1,5}\*)?sqrt\([-0-9./ ]{0,6}\)\Z")))
def test_box_lengths(text):
    try:
        length = Length.parse(text)
    except InputError as error:
        assert "box length" in str(error)
    else:
        assert length.squared > 0 and float(length) > 0
        assert Length.parse(length.text) == length


@fuzz(1500)
@given(st.dictionaries(st.one_of(st.integers(-3, 14), st.text(max_size=3)),
                       st.one_of(st.text(max_size=6), st.fractions(), st.integers(-2, 2)), max_size=4))
def test_steiner_maps(steiner):
    try:
        cfg = Configuration.from_steiner(("1", "1", "1"), steiner)
    except InputError as error:
        assert "edge" in str(error)
    else:
        assert all(t is None or 0 < t < 1 for t in cfg.steiner)


KEYS = ["schema_version", "version", "types", "configurations", "criteria", "box", "face_points", "study",
        "scheme", "generator", "catalogue_version", "id", "name", "code", "nodes", "type", "circumcenter",
        "optimal", "internal_faces", "fvm_adequate", "vertices", "edges", "faces", "face_kinds", "aliases",
        "reference_faces", "example", "kind", "000000000000", "800000000000", "kept", "splits"]
VALUES = st.recursive(
    st.one_of(st.none(), st.booleans(), st.integers(-2, 30), st.floats(allow_nan=True),
              st.sampled_from(["1", "octree", "none", "optimal", "v4f4-8f0284", "v5f5-58e6ed", "bisection",
                               "abcdef012345", "triangle", "sqrt(2)"])),
    lambda children: st.one_of(st.lists(children, max_size=5),
                               st.dictionaries(st.sampled_from(KEYS), children, max_size=6)),
    max_leaves=25,
)


def read_document(text: str) -> None:
    data = parse_yaml(text, "fuzz.yaml")
    kind, data = validated(data, "fuzz.yaml")
    if kind == "catalogue":
        check_catalogue(data, "fuzz.yaml")
    else:
        check_patterns(table_from_data(data, "fuzz.yaml"), None, "fuzz.yaml")


@fuzz(2000)
@given(st.one_of(st.text(max_size=60), VALUES.map(lambda v: yaml.safe_dump(v))))
def test_catalogue_and_pattern_readers(text):
    try:
        read_document(text)
    except FormatError:
        pass


TOKENS = ["tessellate", "diff", "check", "--box", "--code", "--steiner", "--face-points", "--format",
          "--criterion", "1", "2", "0", "-1", "sqrt(2)", "1.4142", "3/2", "nan", "x", "800000000000",
          "8888a0000808", "80000000000g", "0:1/2", "11:3/4", "12:1/2", "0:0", "json", "yaml", "text",
          "octree", "none", "internal_faces", "optimal", "--rev", "HEAD", "/nonexistent.yaml", "--help", ""]


@fuzz(2000)
@given(st.lists(st.sampled_from(TOKENS), max_size=10))
def test_command_lines(argv):
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        try:
            status = main(argv)
        except SystemExit as exit:  # --help and --version exit 0 through argparse
            status = exit.code
    assert status in (0, 1, 2), (argv, status)
    if status == 2:
        assert len(err.getvalue().strip().splitlines()) == 1, (argv, err.getvalue())
        assert "Traceback" not in err.getvalue()


@fuzz(2000)
@given(st.one_of(st.text(alphabet="0123456789+-./eE " + LOOKALIKES, max_size=14),
                 st.from_regex(r"\A[+-]?[0-9]{1,45}(\.[0-9]{1,45})?([eE][+-]?[0-9]{1,3})?\Z"),
                 st.from_regex(r"\A[0-9]{1,45}/[0-9]{1,45}\Z")))
def test_number_grammar(text):
    """parse_rational accepts exactly the ASCII grammar with bounded digits, and reads it exactly."""
    from fractions import Fraction

    cleaned = text.strip(" ")
    try:
        value = parse_rational(text)
    except InputError as error:
        assert str(error).startswith("number ")
        if ORACLE.fullmatch(cleaned) and "e" not in cleaned.lower() and not cleaned.endswith("/0") \
                and not re.fullmatch(r"[+-]?0+/0+|.*/0+", cleaned):
            exact = Fraction(cleaned)
            assert abs(exact.numerator) >= 10**40 or exact.denominator >= 10**40, (text, error)
    else:
        assert ORACLE.fullmatch(cleaned), text
        assert value == Fraction(cleaned)
        assert abs(value.numerator) < 10**40 and value.denominator < 10**40


EDGE_SPELLINGS = st.sampled_from(["0", "00", "000", " 0", "1", "01", "11", "011", "3", "+3", "\uff13", "\u0663", "12"])


@fuzz(1000)
@given(st.lists(st.tuples(EDGE_SPELLINGS, st.sampled_from(["1/2", "1/3", "3/4"])), max_size=4))
def test_steiner_lists_refuse_an_edge_given_twice(pairs):
    """Duplicates are found by value ('0' and '00' are one edge); only ASCII edge numbers 0..11."""
    valid = [e.strip() for e, _ in pairs if e.strip().isascii() and e.strip().isdigit() and int(e) <= 11]
    try:
        cfg = Configuration.from_steiner(("1", "1", "1"), pairs)
    except InputError:
        assert len(valid) < len(pairs) or len({int(e) for e in valid}) < len(valid)
    else:
        assert len(valid) == len(pairs) and len({int(e) for e in valid}) == len(valid)
        assert sum(t is not None for t in cfg.steiner) == len(pairs)
