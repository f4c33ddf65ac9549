"""What commands write: data on stdout, result lines as a terminal shows them, --out held for a run."""

from __future__ import annotations

import argparse
import json

import pytest
import yaml

from cospherical.cli.output import emit, holding_out, path_argument, say
from cospherical.errors import InputError


@pytest.mark.parametrize("text", ["", " ", "\t\n"])
def test_an_empty_path_is_refused_by_the_parser(text, capsys):
    parser = argparse.ArgumentParser(prog="demo")
    parser.add_argument("--out", type=path_argument)
    assert parser.parse_args(["--out", "a b"]).out.name == "a b"
    with pytest.raises(SystemExit) as exit:
        parser.parse_args(["--out", text])
    assert exit.value.code == 2 and "an empty path" in capsys.readouterr().err


@pytest.mark.oracle_pyyaml
@pytest.mark.parametrize("fmt, read", [("json", json.loads), ("yaml", yaml.safe_load)])
def test_emitted_data_reads_back(fmt, read, capsys):
    data = {"box": ["1", "sqrt(2)"], "share": 1e-05, "name": "été", "nested": {"n": [1, 2]}}
    emit(data, fmt)
    assert read(capsys.readouterr().out) == data


def test_a_result_line_cannot_forge_another_or_drive_the_terminal(capsys):
    say("wrote out\nx: ok\x1b[2J")
    out = capsys.readouterr().out
    assert out.count("\n") == 1 and "\x1b" not in out and out.startswith("wrote out\\nx: ok")


def test_out_is_held_for_the_whole_run(tmp_path):
    seen = []

    @holding_out
    def run(args) -> int:
        seen.append(args.out.is_dir())
        if args.out.name == "outer":  # a second run into the same folder while this one holds it
            with pytest.raises(InputError, match="another cospherical run is writing into this folder"):
                run(argparse.Namespace(out=args.out, inner=True))
        return 0

    assert run(argparse.Namespace(out=tmp_path / "outer")) == 0
    assert seen == [True] and (tmp_path / "outer").is_dir()  # the inner run never started
    assert run(argparse.Namespace(out=tmp_path / "outer")) == 0  # released: a later run may
    assert len(seen) == 2


def test_without_out_the_run_is_called_as_is(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)

    @holding_out
    def run(args) -> int:
        return 7

    assert run(argparse.Namespace(out=None)) == 7 and list(tmp_path.iterdir()) == []
