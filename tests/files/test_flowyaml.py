"""Pattern tables in our one-line-per-entry form: read by splitting lines, any other form told apart at once."""

from __future__ import annotations

from pathlib import Path

import pytest

from cospherical.errors import FormatError
from cospherical.files.flowyaml import decode_entry

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
