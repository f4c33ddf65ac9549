"""Fuzzing the readers and the command line: no input may fail with anything but the clean error.

Counts (max_examples): codes 2500, Steiner maps 1500, Steiner lists 1000, YAML documents 2000,
command lines 2000: 9,000 generated inputs with ``pytest --full``, a quarter of each count by default
(``sampling.examples``: fresh inputs every run). The number grammar and the box lengths are fuzzed
where their module's tests are, core/test_exact.py.
"""

from __future__ import annotations

import io
from contextlib import redirect_stderr, redirect_stdout

import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sampling import examples

from cospherical import Configuration, InputError
from cospherical.cli import main
from cospherical.errors import FormatError
from cospherical.files.yamlio import parse_yaml
from cospherical.formats.check import check_catalogue, check_patterns, validated
from cospherical.formats.patterns import table_from_data


def fuzz(n: int):
    return settings(max_examples=examples(n), deadline=None, suppress_health_check=list(HealthCheck))


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
