"""Local process pools: a pool left by an error, or stopped by the command, ends its running calls at once."""

from __future__ import annotations

import os
import time

import pytest

from cospherical.execution.pool import process_pool, stop_all


def _gone(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    return False


def test_a_pool_left_by_an_error_kills_its_running_calls_at_once():
    start = time.monotonic()
    with pytest.raises(RuntimeError), process_pool(1) as pool:
        worker = pool.submit(os.getpid).result()
        running = pool.submit(time.sleep, 120)  # a chunk of minutes: shutdown() alone would wait for it
        raise RuntimeError("the command failed meanwhile")
    assert time.monotonic() - start < 30 and _gone(worker) and running.done()


def test_stop_all_stops_every_running_pool():
    with process_pool(1) as pool:
        worker = pool.submit(os.getpid).result()
        pool.submit(time.sleep, 120)
        start = time.monotonic()
        stop_all()  # what Ctrl-C and SIGTERM call, wherever the command is
        assert time.monotonic() - start < 30 and _gone(worker)
