"""Local process pools: a pool left by an error, or stopped by the command, ends its running calls at once.

Each case runs in a fresh interpreter, as a command would: the pool registry and the signal
handlers that other tests leave in a test worker's process are not the command's, and a
pool's workers are killed there, never beside the test runner's own state.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

_GONE = """
import os, time
from concurrent.futures.process import BrokenProcessPool

import pytest

from cospherical.execution.pool import process_pool, stop_all


def gone(pid, within=10.0):
    # killed and reaped: a killed worker stays a zombie (os.kill(pid, 0) succeeds) until the pool's
    # thread reaps it, which a loaded machine delays; bounded, well inside the 30 s the tests allow
    deadline = time.monotonic() + within
    while True:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return True
        if time.monotonic() > deadline:
            return False
        time.sleep(0.02)
"""


def _run(body: str) -> None:
    result = subprocess.run([sys.executable, "-c", _GONE + textwrap.dedent(body)], capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 0 and result.stderr == "", result.stderr


def test_a_pool_left_by_an_error_kills_its_running_calls_at_once():
    _run("""
        start = time.monotonic()
        with pytest.raises(RuntimeError), process_pool(1) as pool:
            worker = pool.submit(os.getpid).result()
            running = pool.submit(time.sleep, 120)  # a chunk of minutes: shutdown() alone would wait for it
            while not running.running():  # handed to the worker (a call still queued is only cancelled)
                time.sleep(0.01)
            raise RuntimeError("the command failed meanwhile")
        assert time.monotonic() - start < 30
        assert gone(worker)
        # failed once the pool's management thread has seen its worker die: bounded, not instant
        assert isinstance(running.exception(timeout=10), BrokenProcessPool)
        """)


def test_stop_all_stops_every_running_pool():
    _run("""
        with process_pool(1) as pool:
            worker = pool.submit(os.getpid).result()
            pool.submit(time.sleep, 120)
            start = time.monotonic()
            stop_all()  # what Ctrl-C and SIGTERM call, wherever the command is
            assert time.monotonic() - start < 30
            assert gone(worker)
            # and the pool's management thread has ended: the interpreter's exit would otherwise wake it
            # through a pipe it may be closing that moment ("Bad file descriptor" printed at exit)
            import threading
            assert [t.name for t in threading.enumerate() if t is not threading.main_thread()] == []
        """)
