"""The command line, run as a user runs it (a real subprocess)."""

import json
import subprocess
import sys

import pytest
import yaml


def cospherical(*args):
    return subprocess.run([sys.executable, "-m", "cospherical", *args], capture_output=True, text=True)


def test_tessellate_json_contract():
    result = cospherical("tessellate", "--box", "1", "1", "1", "--code", "800000000000")
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    assert data["box"] == ["1", "1", "1"] and data["code"] == "800000000000"
    assert data["nodes"]["8"] == [0.5, 0.0, 0.0]
    assert set(data["nodes"]) == {str(i) for i in range(9)}
    assert len(data["elements"]) == 4
    for element in data["elements"]:
        assert {"type", "name", "nodes", "vertices", "edges", "faces", "circumcenter"} <= set(element)
        assert element["name"] == "Rectangular Pyramid" and len(element["nodes"]) == 5
        assert (element["vertices"], element["edges"], element["faces"]) == (5, 8, 5)
    assert data["fvm_adequate"] is True


def test_tessellate_steiner_and_yaml_agree_with_code():
    by_code = json.loads(cospherical("tessellate", "--box", "1", "sqrt(2)", "1.4142", "--code", "800080000008").stdout)
    result = cospherical("tessellate", "--box", "1", "sqrt(2)", "1.4142", "--steiner", "0:1/2", "4:0.5", "11:8/16",
                         "--format", "yaml")
    assert result.returncode == 0, result.stderr
    assert yaml.safe_load(result.stdout) == by_code


def test_output_is_deterministic():
    args = ("tessellate", "--box", "1", "2", "4", "--code", "88808a000c01", "--face-points", "none")
    assert cospherical(*args).stdout == cospherical(*args).stdout


@pytest.mark.parametrize(
    "args, needle",
    [
        (["tessellate", "--box", "1", "1", "1", "--code", "80000000000"], "configuration code"),
        (["tessellate", "--box", "1", "0", "1"], "box length '0'"),
        (["tessellate", "--box", "1", "nan", "1"], "box length 'nan'"),
        (["tessellate", "--box", "1", "1", "1", "--steiner", "0:3/2"], "edge 0"),
        (["tessellate", "--box", "1", "1", "1", "--steiner", "12:1/2"], "edge '12'"),
        (["tessellate", "--box", "1", "1", "1", "--steiner", "0"], "EDGE:T"),
        (["tessellate", "--box", "1", "1", "1", "--steiner", "0:1/2", "0:1/3"], "given twice"),
        (["tessellate", "--box", "1", "1"], "--box"),
        (["tessellate", "--box", "1", "1", "1", "--face-points", "all"], "face-points"),
        (["tessellate", "--box", "1", "1", "1", "--code", "800000000000", "--steiner", "0:1/2"], "not allowed"),
        (["tessellate"], "--box"),
        (["frobnicate"], "frobnicate"),
        ([], "command"),
    ],
)
def test_usage_errors_are_one_line_exit_2(args, needle):
    result = cospherical(*args)
    assert result.returncode == 2
    assert result.stdout == ""
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert needle in lines[0] and "Traceback" not in result.stderr


def test_main_freezes_the_collector_only_as_the_process_command(monkeypatch, capsys):
    # Run as the process's command (no argument list), main moves what the command made
    # out of the cycle collector's reach before the process exits; called with an
    # argument list (tests, a program embedding it) it leaves the collector as it was.
    import gc

    from cospherical.cli import main

    command = ["tessellate", "--box", "1", "1", "1", "--code", "800000000000"]
    frozen = gc.get_freeze_count()
    assert main(command) == 0, capsys.readouterr().err
    assert gc.get_freeze_count() == frozen
    monkeypatch.setattr(sys, "argv", ["cospherical", *command])
    try:
        assert main() == 0, capsys.readouterr().err
        assert gc.get_freeze_count() > frozen
    finally:
        gc.unfreeze()


def test_each_study_family_has_its_own_help(capsys):
    from cospherical.cli import main

    texts = {}
    for family in ("bisection", "leaves", "intersection"):
        with pytest.raises(SystemExit) as exit:
            main(["study", family, "--help"])
        assert exit.value.code == 0
        texts[family] = capsys.readouterr().out
    assert len(set(texts.values())) == 3
    assert "--resume" in texts["intersection"] and "--resume" not in texts["bisection"]
    assert "--element" in texts["bisection"] and "--element" not in texts["leaves"]
    assert "--face-points" not in texts["leaves"] and "--box" not in texts["intersection"]
    assert main(["study", "bisection", "--resume"]) == 2  # hidden, still refused by name
    assert "option of the intersection study only" in capsys.readouterr().err


def test_the_scheduler_option_says_it_must_be_a_scheduler_you_run(capsys):
    # Dask unpickles what the scheduler sends: connecting to one is trusting it with your account.
    # The help of each --scheduler says so, and the Dask how-to says why, in one place.
    import re
    from pathlib import Path

    from cospherical.cli import main

    for argv in (["mesh", "--help"], ["study", "intersection", "--help"]):
        with pytest.raises(SystemExit):
            main(argv)
        text = " ".join(capsys.readouterr().out.split())
        start = text.rindex("--scheduler tcp://HOST:PORT")  # the option's entry, after the usage line
        help_text = text[start:text.index("--scheduler-timeout", start)]
        assert "must be a scheduler you run" in help_text and "unpickles" in help_text, help_text
    docs = Path(__file__).resolve().parents[1] / "docs"
    warned = [p.name for p in docs.rglob("*.md") if re.search(r"only to a scheduler you run", p.read_text())]
    assert warned == ["dask.md"]
