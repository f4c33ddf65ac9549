"""Where the work units run (``cospherical.execution``): bad backend choices and unreachable Dask
schedulers are one line, at once.

Through the real command (``study intersection``), as a user meets them: every refusal
is exit 2 with one line on stderr, before any worker process starts; a scheduler where
nothing listens is refused without waiting for the timeout, one that accepts and never
answers within it.
"""

from __future__ import annotations

import socket
import time

import pytest
from commands import cospherical

from cospherical.cli import main


def _one_line(rc: int, err: str, needle: str) -> None:
    lines = err.strip().splitlines()
    assert rc == 2 and len(lines) == 1 and "Traceback" not in err, (rc, err)
    assert needle.lower() in lines[0].lower(), lines[0]


def refused(capsys, *argv, needle: str = "") -> None:
    _one_line(main([str(a) for a in argv]), capsys.readouterr().err, needle)


def refused_in_a_process(*argv, needle: str = "") -> None:
    result = cospherical(*argv)
    _one_line(result.returncode, result.stderr, needle)


def _closed_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_bad_and_unreachable_schedulers_are_one_line():
    refused_in_a_process("study", "intersection", "--resolution", "2", "--scheduler", "garbage://x")
    start = time.monotonic()
    refused_in_a_process("study", "intersection", "--resolution", "2", "--scheduler",
                         f"tcp://127.0.0.1:{_closed_port()}", "--scheduler-timeout", "2", needle="scheduler")
    assert time.monotonic() - start < 30


def test_a_scheduler_port_where_nothing_listens_is_one_line_at_once(capsys):
    # dask's connect retried the refused connection for the whole default timeout (30 s)
    start = time.monotonic()
    refused(capsys, "study", "intersection", "--resolution", "2", "--scheduler", f"tcp://127.0.0.1:{_closed_port()}",
            needle="cannot connect: nothing listens on port")
    assert time.monotonic() - start < 5


def test_a_scheduler_port_that_never_answers_is_one_line_within_the_timeout(capsys):
    # the kernel accepts the connection (the backlog), nothing answers: dask's Client waited for good
    with socket.socket() as silent:
        silent.bind(("127.0.0.1", 0))
        silent.listen(8)
        start = time.monotonic()
        refused(capsys, "study", "intersection", "--resolution", "2", "--scheduler",
                f"tcp://127.0.0.1:{silent.getsockname()[1]}", "--scheduler-timeout", "1",
                needle="cannot connect: no answer within 1 s")
        assert time.monotonic() - start < 20


@pytest.mark.parametrize("option", [["--jobs", "100000"], ["--jobs", "-1"], ["--dask-workers", "100000"]])
def test_worker_counts_are_bounded_before_any_process_starts(capsys, option):
    # 100,000 local workers: each a Python with numpy; the run went on for minutes before failing
    refused(capsys, "study", "intersection", "--resolution", "2", *option,
            needle=f"{option[0]} {option[1]}: must be an integer from 1 to 256")
