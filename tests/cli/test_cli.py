"""The command line as a whole, run as a user runs it (a real subprocess): usage errors of every command,
every option's help, the collector frozen only as the process's command, the scheduler option's warning, a
signal ending the run as signalled whatever a library makes of it."""

import re
import signal
import sys
import time
from pathlib import Path

import pytest
from commands import cospherical


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
        # numbers past int()'s 4,300 digits: its ValueError was a traceback, the value shown cut short
        (["tessellate", "--box", "1", "1", "1", "--steiner", "9" * 5000 + ":1/2"], "not an edge number"),
        (["tessellate", "--box", "1", "1", "1", "--element", "prism", "--code", "888888888", "--faces", "9" * 5000],
         "not a face number"),
        (["tessellate", "--box", "1", "1", "1", "--element", "prism", "--code", "888888888+" + "x" * 50_000],
         "malformed point suffix"),
        # Path("") is the current folder: the outputs went wherever the command ran
        (["mesh", "--domain", "1", "1", "1", "--levels", "2", "--out", ""], "an empty path"),
        (["study", "bisection", "--out", " "], "an empty path"),
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
    assert len(lines[0]) < 300  # the input is named, not echoed whole


def test_main_freezes_the_collector_only_as_the_process_command(monkeypatch, capsys):
    # Run as the process's command (no argument list), main moves what the command made
    # out of the cycle collector's reach before the process exits; called with an
    # argument list (tests, a program embedding it) it leaves the collector as it was.
    import gc

    from cospherical.cli import main

    command = ["tessellate", "--box", "1", "1", "1", "--code", "800000000000"]
    frozen = gc.get_freeze_count()
    threshold = gc.get_threshold()
    assert main(command) == 0, capsys.readouterr().err
    assert gc.get_freeze_count() == frozen and gc.get_threshold() == threshold
    monkeypatch.setattr(sys, "argv", ["cospherical", *command])
    try:
        assert main() == 0, capsys.readouterr().err
        assert gc.get_freeze_count() > frozen
        # and the collector's first generation runs seldom: the command's objects hold almost no cycles
        assert gc.get_threshold() == (50_000, *threshold[1:])
    finally:
        gc.unfreeze()
        gc.set_threshold(*threshold)


def test_main_as_the_process_command_starts_one_openblas_thread_unless_asked(monkeypatch, capsys):
    # OpenBLAS starts a spinning thread per core as numpy loads (~0.05 s CPU of every run) for linear
    # algebra no command calls: run as the process's command, main asks for one before numpy loads,
    # unless the environment says otherwise; called with an argument list it leaves the environment alone.
    import os
    import subprocess

    from cospherical.cli import main

    import gc

    command = ["tessellate", "--box", "1", "1", "1", "--code", "800000000000"]
    threshold = gc.get_threshold()
    monkeypatch.delenv("OPENBLAS_NUM_THREADS", raising=False)
    assert main(command) == 0, capsys.readouterr().err
    assert "OPENBLAS_NUM_THREADS" not in os.environ
    monkeypatch.setattr(sys, "argv", ["cospherical", *command])
    try:
        assert main() == 0, capsys.readouterr().err
        assert os.environ["OPENBLAS_NUM_THREADS"] == "1"
        monkeypatch.setenv("OPENBLAS_NUM_THREADS", "3")
        assert main() == 0, capsys.readouterr().err
        assert os.environ["OPENBLAS_NUM_THREADS"] == "3"
    finally:
        gc.unfreeze()
        gc.set_threshold(*threshold)
    # in a fresh process: asked before numpy loads, OpenBLAS starts no thread (the process keeps its one)
    script = ("import sys\nfrom cospherical.cli import main\nsys.argv = ['cospherical', '--version']\n"
              "try:\n    main()\nexcept SystemExit:\n    pass\nimport os, numpy\n"
              "print(len(os.listdir('/proc/self/task')))")
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")}
    found = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, check=True)
    assert found.stdout.split()[-1] == "1", found


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
    docs = Path(__file__).resolve().parents[2] / "docs"
    warned = [p.name for p in docs.rglob("*.md") if re.search(r"only to a scheduler you run", p.read_text())]
    assert warned == ["dask.md"]


@pytest.mark.parametrize("sig, status", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_a_signal_that_a_library_turns_into_its_own_error_still_ends_the_run_as_signalled(
        monkeypatch, capsys, sig, status):
    # numba reports an exception raised by a signal handler during a compiled call as
    # "SystemError: CPUDispatcher(...) returned a result with an exception set": the run
    # must still end as the signal says, with one line and no traceback.
    import cospherical.cli as cli
    import cospherical.cli.tessellate as tessellate

    def compiled_call(args):
        try:
            signal.raise_signal(sig)
        except BaseException as error:
            raise SystemError("CPUDispatcher(<function>) returned a result with an exception set") from error

    monkeypatch.setattr(tessellate, "run", compiled_call)
    handlers = signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGINT)
    try:
        try:
            code = cli.main(["tessellate", "--box", "1", "1", "1", "--code", "800000000000"])
        except SystemExit as exit:
            code = exit.code
    finally:
        signal.signal(signal.SIGTERM, handlers[0])
        signal.signal(signal.SIGINT, handlers[1])
    assert code == status
    assert capsys.readouterr().err.strip() == ("cospherical: terminated" if sig == signal.SIGTERM
                                               else "cospherical: interrupted")


@pytest.mark.parametrize("module", ["numba.core.compiler", "logging"])
def test_a_signal_held_back_where_it_cannot_unwind_is_not_sent_again_after_the_run(monkeypatch, capsys, module):
    # SIGTERM arriving inside numba's compiler (unwinding there crashes the process) or inside
    # logging's fork hooks (an exception there is printed as "Exception ignored" with a
    # traceback, then dropped) is held back and re-sent shortly: the code it arrived in runs on.
    # When the run ends first (as terminated), the held-back signal must not arrive later.
    import os

    import cospherical.cli as cli
    import cospherical.cli.tessellate as tessellate

    compiler = {"__name__": module, "os": os, "signal": signal, "reached": []}
    exec("def compile_(args):\n    os.kill(os.getpid(), signal.SIGTERM)\n    reached.append(True)\n    return 0\n",
         compiler)
    monkeypatch.setattr(tessellate, "run", compiler["compile_"])
    handlers = signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGINT)
    try:
        with pytest.raises(SystemExit) as ended:
            cli.main(["tessellate", "--box", "1", "1", "1", "--code", "800000000000"])
        assert ended.value.code == 143 and compiler["reached"] == [True]
        time.sleep(0.4)  # a re-sent SIGTERM would raise SystemExit here
    finally:
        signal.signal(signal.SIGTERM, handlers[0])
        signal.signal(signal.SIGINT, handlers[1])
    assert capsys.readouterr().err.strip() == "cospherical: terminated"


def test_every_option_has_help():
    from cospherical.cli import build_parser

    parser = build_parser()
    subparsers = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    missing = [f"{name} {action.dest}" for name, sub in subparsers.choices.items() for action in sub._actions
               if not action.help and action.dest != "help"]
    assert missing == []


# A file name may hold any byte but / and NUL: line breaks of every kind, ESC sequences, a bell, a
# bidirectional override. An error line names it escaped: one line, nothing that drives the terminal.
HOSTILE_NAME = "out\nfake: ok\r\x1b[2J\x85\u2028\u2029\u202e\x07\x0b"


def _error_paths(tmp):
    blocked = tmp / "a-file"  # a file where a folder must be made: the write fails, naming the path
    blocked.write_text("")
    missing, under = tmp / HOSTILE_NAME, blocked / HOSTILE_NAME
    return {
        "check": ["check", missing], "diff": ["diff", missing, missing],
        "render": ["render", "--summary", missing, "--out", tmp / "o"],
        "mesh --leaves": ["mesh", "--domain", "1", "1", "1", "--leaves", missing],
        "mesh --out": ["mesh", "--domain", "1", "1", "1", "--levels", "1", "--refine", "point:0.5,0.5,0.5",
                       "--out", under],
        "tessellate --vtu": ["tessellate", "--box", "1", "1", "1", "--vtu", under / "m.vtu"],
        "study --out": ["study", "bisection", "--out", under],
        "sweep --out": ["sweep", "--ray", "1,2,2", "--out", under],
        "reproduce --root": ["reproduce", "--root", under],
        "an unknown option": ["check", "x.yaml", "--x\x1b[2J\n\u2028\x85"],
        "mesh --refine": ["mesh", "--domain", "1", "1", "1", "--levels", "2", "--refine", HOSTILE_NAME],
        "mesh --refine, long": ["mesh", "--domain", "1", "1", "1", "--levels", "2", "--refine",
                                "sphere:0.5,0.5,0.5," + "9" * 5000 + HOSTILE_NAME],
        "mesh --refine, long kind": ["mesh", "--domain", "1", "1", "1", "--levels", "2", "--refine",
                                     "x" * 5000 + HOSTILE_NAME + ":1"],
    }


@pytest.mark.parametrize("case", [
    "check", "diff", "render", "mesh --leaves", "mesh --out", "tessellate --vtu", "study --out", "sweep --out",
    "reproduce --root", "an unknown option", "mesh --refine", "mesh --refine, long", "mesh --refine, long kind"])
def test_an_error_line_names_a_hostile_path_or_value_on_one_printable_line(tmp_path, capsys, case):
    from cospherical.cli import main

    argv = [str(word) for word in _error_paths(tmp_path)[case]]
    assert main(argv) == 2
    captured = capsys.readouterr()
    lines = captured.err.splitlines()  # every kind of line break: NEL, LS and PS too
    assert len(lines) == 1 and captured.err.endswith("\n"), captured.err
    assert lines[0].isprintable() and len(lines[0]) < 300, lines[0]
    assert "\\x1b[2J" in lines[0] or "..." in lines[0], lines[0]  # named, escaped (or cut before it)


def test_a_result_line_names_a_hostile_path_on_one_printable_line(tmp_path, capsys):
    # stdout too: check's "ok" line, render's "wrote" line and diff's file names name a path as
    # written, escaped; a newline in it must not forge a line ("fake: ok"), an ESC not reach the terminal
    from cospherical.cli import main

    folder = tmp_path / HOSTILE_NAME
    folder.mkdir()
    catalogue = (Path(__file__).resolve().parents[2] / "catalogue" / "catalogue.yaml").read_text()
    old, new = folder / "old.yaml", folder / "new.yaml"
    old.write_text(catalogue)
    new.write_text(re.sub(r"(?m)^version: .*$", "version: abcdef012345", catalogue, count=1))
    summary = Path(__file__).resolve().parents[2] / "results" / "bisection-1x1x1.json"
    for argv, status in ((["check", old], 0), (["diff", old, new], 1),
                         (["render", "--summary", summary, "--out", folder / "tables"], 0)):
        assert main([str(word) for word in argv]) == status
        out = capsys.readouterr().out
        lines = out.splitlines()  # every kind of line break: NEL, LS and PS too
        assert lines and out.endswith("\n") and all(line.isprintable() for line in lines), out
        assert not any(line.startswith("fake: ok") for line in lines), out
        assert "out\\nfake: ok\\r\\x1b[2J" in lines[0], lines[0]


def test_an_os_error_names_its_file_on_one_printable_line(capsys, monkeypatch):
    import errno

    import cospherical.cli.check
    from cospherical.cli import main

    def refused(args):
        raise OSError(errno.EACCES, "Permission denied", HOSTILE_NAME)

    monkeypatch.setattr(cospherical.cli.check, "run", refused)
    assert main(["check", "x.yaml"]) == 2
    line = capsys.readouterr().err
    assert line.splitlines() == [line[:-1]] and line[:-1].isprintable(), line
    assert line.startswith("cospherical: error: out\\nfake: ok\\r\\x1b[2J") and "Permission denied" in line
