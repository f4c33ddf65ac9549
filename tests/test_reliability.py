"""Bad input through the real CLI, deep checks of files, and interrupted runs."""

from __future__ import annotations

import copy
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cospherical import Box
from cospherical.catalogue import catalogue_path, load_catalogue
from cospherical.files.yamlio import dump_yaml, load_yaml
from cospherical.formats.patterns import write_patterns
from cospherical.studies.engine import run_study

ROOT = Path(__file__).resolve().parents[1]


def cospherical(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "cospherical", *args], capture_output=True, text=True, cwd=cwd)


def one_clean_line(result, needle: str) -> None:
    assert result.returncode == 2, (result.returncode, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.stderr, result.stderr
    assert needle in lines[0], lines[0]


@pytest.fixture(scope="module")
def small_table(tmp_path_factory):
    """A pattern table of a few configurations of the 1x2x4 box, as data to break."""
    path = tmp_path_factory.mktemp("small") / "small.yaml"
    codes = ["000000000000", "800000000000", "880000000000", "888888888888"]
    study = run_study("bisection", Box.parse(("1", "2", "4")), codes)
    write_patterns(study, path, load_catalogue(catalogue_path())["version"])
    return load_yaml(path)


def write(tmp_path, name, data) -> str:
    path = tmp_path / name
    dump_yaml(data, path)
    return str(path)


def test_good_files_pass_the_deep_check(tmp_path, small_table):
    result = cospherical("check", str(ROOT / "catalogue" / "catalogue.yaml"), write(tmp_path, "good.yaml", small_table))
    assert result.returncode == 0, result.stderr
    assert "ok, catalogue of" in result.stdout and "ok, pattern table of 4 configurations" in result.stdout


@pytest.mark.parametrize(
    "edit, needle",
    [
        (lambda d: d["configurations"]["800000000000"]["optimal"][0].update(type="v5f5-ffffff"), "unknown element type"),
        (lambda d: d["configurations"]["800000000000"]["optimal"][0].update(nodes=[0, 1, 2, 3, 26]), "node 26 is not a point"),
        (lambda d: d["configurations"]["800000000000"]["optimal"][0].update(nodes=[0, 1, 2, 3, 40]), "800000000000"),
        (lambda d: d["configurations"]["800000000000"]["optimal"].pop(), "do not fill the box"),
        (lambda d: d["configurations"]["880000000000"]["optimal"][0].update(
            nodes=list(reversed(d["configurations"]["880000000000"]["optimal"][0]["nodes"]))), "configurations/880000000000"),
        (lambda d: d["configurations"]["800000000000"]["optimal"].append(  # a copy: a shared object is a YAML alias
            copy.deepcopy(d["configurations"]["800000000000"]["optimal"][0])), "do not fill the box"),
        (lambda d: d["configurations"]["000000000000"].update(internal_faces="internal_edges_and_faces"), "internal_faces"),
        (lambda d: d.update(box=["1", "0", "4"]), "box"),
        (lambda d: d.update(schema_version=2), "schema_version"),
    ],
)
def test_bad_pattern_tables_are_refused(tmp_path, small_table, edit, needle):
    data = copy.deepcopy(small_table)
    edit(data)
    one_clean_line(cospherical("check", write(tmp_path, "bad.yaml", data)), needle)


def test_repeated_configuration_codes_are_refused(tmp_path, small_table):
    text = Path(write(tmp_path, "good.yaml", small_table)).read_text().splitlines()
    start = text.index("configurations:") + 1
    end = next(i for i in range(start + 1, len(text)) if text[i].startswith("  '"))
    duplicated = text[: end] + text[start:end] + text[end:]
    path = tmp_path / "twice.yaml"
    path.write_text("\n".join(duplicated[:200]) + "\n")
    one_clean_line(cospherical("check", str(path)), "repeated key '000000000000'")


@pytest.mark.parametrize(
    "edit, needle",
    [
        (lambda d: d["types"].append(copy.deepcopy(d["types"][0])), "appears more than once"),
        (lambda d: d["types"][0].update(edges=99), "V/E/F"),
        (lambda d: d["types"][0]["reference_faces"][0].update(nodes=[0, 1, 9]), "reference_faces"),
        (lambda d: d["criteria"]["internal_faces"]["kept"].append("v4f4-000000"), "unknown type"),
        (lambda d: d["types"][0].pop("code"), "code"),
    ],
)
def test_bad_catalogues_are_refused(tmp_path, edit, needle):
    data = load_yaml(ROOT / "catalogue" / "catalogue.yaml")
    edit(data)
    one_clean_line(cospherical("check", write(tmp_path, "bad-catalogue.yaml", data)), needle)


@pytest.mark.parametrize(
    "content, needle",
    [("", "neither a catalogue"), ("[1, 2", "line"), ("a: !!python/object:os.system x\n", "line"),
     ("\xff\xfe", "cannot read")],
)
def test_unreadable_files_are_refused(tmp_path, content, needle):
    path = tmp_path / "junk.yaml"
    path.write_bytes(content.encode("latin-1"))
    one_clean_line(cospherical("check", str(path)), needle)
    one_clean_line(cospherical("diff", str(path), str(path)), needle)


def test_missing_files_are_refused(tmp_path):
    one_clean_line(cospherical("check", str(tmp_path / "nothere.yaml")), "nothere.yaml: cannot read")
    one_clean_line(cospherical("render", "--summary", str(tmp_path / "nothere.json"), "--out", str(tmp_path)),
                   "cannot read")


def snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_interrupted_study_leaves_complete_outputs_and_no_temporary_files(tmp_path, sig):
    args = [sys.executable, "-m", "cospherical", "study", "bisection", "--box", "1", "2", "4", "--out", str(tmp_path)]
    assert subprocess.run(args, capture_output=True).returncode == 0
    before = snapshot(tmp_path)
    assert len(before) == 2
    # from 1 s on: a signal during the interpreter's own start-up is outside the program
    for delay in (1.0, 1.5, 2.0, 3.0, 4.0, 5.0):
        process = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        time.sleep(delay)
        process.send_signal(sig)
        _, stderr = process.communicate(timeout=60)
        if process.returncode != 0:
            assert process.returncode in (130, 143, -sig), process.returncode
            assert b"Traceback" not in stderr, stderr
        assert snapshot(tmp_path) == before, f"outputs changed after a signal at {delay} s"
        assert not list(tmp_path.glob(".*")), f"temporary files left after a signal at {delay} s"


def _children(pid: int) -> list[int]:
    found = []
    for entry in Path("/proc").iterdir():
        try:
            if entry.name.isdigit() and int((entry / "stat").read_text().rsplit(")", 1)[1].split()[1]) == pid:
                found.append(int(entry.name))
        except (OSError, IndexError, ValueError):
            pass  # a process that ended meanwhile
    return found


def test_a_terminated_pattern_table_leaves_no_worker_and_no_table(tmp_path):
    # SIGTERM while the workers build the table: the command ends at once, its
    # workers with it, and no partial table is left (the study's own files are complete).
    args = [sys.executable, "-m", "cospherical", "study", "intersection", "--resolution", "4", "--jobs", "2",
            "--patterns", "--out", str(tmp_path)]
    process = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    workers: list[int] = []
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not (tmp_path / "intersection-r4-edge.json").exists():
        workers = _children(process.pid) or workers
        time.sleep(0.05)
    time.sleep(1.0)  # into the table's passes
    workers = _children(process.pid) or workers
    assert workers and process.poll() is None, "the study ended before the table was being built"
    start = time.monotonic()
    process.send_signal(signal.SIGTERM)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 143 and b"Traceback" not in stderr, stderr
    assert time.monotonic() - start < 10
    time.sleep(0.5)
    assert not [pid for pid in workers if Path(f"/proc/{pid}").exists()], "a worker outlived the command"
    assert not list(tmp_path.glob("*patterns*")) and not list(tmp_path.glob(".*"))


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


def test_a_signal_held_back_during_compilation_is_not_sent_again_after_the_run(monkeypatch, capsys):
    # SIGTERM arriving inside numba's compiler is held back and re-sent shortly; when the
    # run ends first (as terminated), the held-back signal must not arrive later.
    import os

    import cospherical.cli as cli
    import cospherical.cli.tessellate as tessellate

    compiler = {"__name__": "numba.core.compiler", "os": os, "signal": signal}
    exec("def compile_(args):\n    os.kill(os.getpid(), signal.SIGTERM)\n    return 0\n", compiler)
    monkeypatch.setattr(tessellate, "run", compiler["compile_"])
    handlers = signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGINT)
    try:
        with pytest.raises(SystemExit) as ended:
            cli.main(["tessellate", "--box", "1", "1", "1", "--code", "800000000000"])
        assert ended.value.code == 143
        time.sleep(0.4)  # a re-sent SIGTERM would raise SystemExit here
    finally:
        signal.signal(signal.SIGTERM, handlers[0])
        signal.signal(signal.SIGINT, handlers[1])
    assert capsys.readouterr().err.strip() == "cospherical: terminated"
