"""Unreadable and missing files through the CLI, and interrupted runs of the real command.

The refusals run ``cospherical.cli.main`` in the test's process (the command's code, without a
second of start-up each); one runs as a process, as a user meets it.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from commands import cospherical, in_process, one_clean_line



@pytest.mark.parametrize(
    "content, needle",
    [("", "neither a catalogue"), ("[1, 2", "line"), ("a: !!python/object:os.system x\n", "line"),
     ("\xff\xfe", "cannot read")],
)
def test_unreadable_files_are_refused(tmp_path, capsys, content, needle):
    path = tmp_path / "junk.yaml"
    path.write_bytes(content.encode("latin-1"))
    one_clean_line(in_process(capsys, "check", path), needle)
    one_clean_line(in_process(capsys, "diff", path, path), needle)


def test_missing_files_are_refused(tmp_path, capsys):
    one_clean_line(cospherical("check", str(tmp_path / "nothere.yaml")), "nothere.yaml: cannot read")
    one_clean_line(in_process(capsys, "render", "--summary", tmp_path / "nothere.json", "--out", tmp_path),
                   "cannot read")


def snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_interrupted_study_leaves_complete_outputs_and_no_temporary_files(tmp_path):
    # one complete run, then runs over it stopped by either signal (the complete run made once for both)
    args = [sys.executable, "-m", "cospherical", "study", "bisection", "--box", "1", "2", "4", "--out", str(tmp_path)]
    start = time.monotonic()
    assert subprocess.run(args, capture_output=True).returncode == 0
    whole = time.monotonic() - start  # this machine's run, at its load now
    before = snapshot(tmp_path)
    assert len(before) == 2
    # from 1 s on: a signal during the interpreter's own start-up is outside the program. Four moments
    # of the run, taken from the complete run's length so that they fall inside it on a fast machine as on
    # a loaded one (fixed delays of 3 to 5 s came after the end on a quiet machine): the start-up, the study,
    # the study's end and the writing; each signal at two of them. Both signals end the run through the same
    # exit path (cli/__init__.py), which test_hostile.py and test_outputs.py also interrupt at other moments
    for sig, delay in ((signal.SIGINT, 1.0), (signal.SIGTERM, max(1.2, 0.6 * whole)),
                       (signal.SIGINT, max(1.4, 0.8 * whole)), (signal.SIGTERM, max(1.6, 0.95 * whole))):
        process = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        time.sleep(delay)
        process.send_signal(sig)
        _, stderr = process.communicate(timeout=60)
        if process.returncode != 0:
            assert process.returncode in (130, 143, -sig), (sig, process.returncode)
            assert b"Traceback" not in stderr, stderr
        assert snapshot(tmp_path) == before, f"outputs changed after signal {sig} at {delay} s"
        assert not list(tmp_path.glob(".*")), f"temporary files left after signal {sig} at {delay} s"


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
    time.sleep(0.3)  # into the table's passes (the assertion below fails if the table was already made)
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
