"""The error hierarchy and the two ways an error line names what came from outside."""

from __future__ import annotations

import pytest

from cospherical.cli import main
from cospherical.errors import CosphericalError, FormatError, InputError, UsageError, one_line, shown


def test_every_error_is_a_cospherical_error_and_a_bad_input_a_value_error():
    assert issubclass(FormatError, InputError) and issubclass(InputError, ValueError)
    assert all(issubclass(kind, CosphericalError) for kind in (FormatError, InputError, UsageError))


@pytest.mark.parametrize("value", ["x" * 100_000, b"\x00" * 5000, list(range(10_000)), 10 ** 5000],
                         ids=["text", "bytes", "list", "a 5000-digit integer"])
def test_shown_names_a_value_in_a_bounded_line(value):
    text = shown(value)
    assert len(text) <= 50 and "\n" not in text


def test_one_line_keeps_a_line_one_line_and_the_terminal_untouched():
    hostile = "out\nfake: ok\r\x1b[2J\u2028\u202e\x85end"
    line = one_line(hostile)
    assert line.isprintable() and line.startswith("out") and line.endswith("end")
    assert one_line("plain text: kept") == "plain text: kept"


def test_the_command_line_turns_an_input_error_into_one_line_and_status_2(capsys, tmp_path):
    bad = tmp_path / "bad\nname.yaml"
    bad.write_text("not: [a, table")
    assert main(["check", str(bad)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "bad\\nname.yaml" in err and "Traceback" not in err
