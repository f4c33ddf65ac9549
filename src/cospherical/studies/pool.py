"""Local process pools whose workers never outlive the command."""

from __future__ import annotations

import os
import signal
from concurrent.futures import ProcessPoolExecutor

__all__ = ["die_with_parent", "process_pool"]


def process_pool(jobs: int) -> ProcessPoolExecutor:
    """A pool of ``jobs`` worker processes that end when this process ends, even by SIGKILL."""
    return ProcessPoolExecutor(max_workers=jobs, initializer=die_with_parent, initargs=(os.getpid(),))


def die_with_parent(parent: int) -> None:
    """Make a pool worker end when the command that started it ends, even by SIGKILL.

    The kernel sends SIGKILL to the worker when its parent dies (Linux
    ``PR_SET_PDEATHSIG``); where that is not available, or the parent died
    before it was set, a watchdog thread sees the parent change and exits.
    """
    import ctypes
    import threading
    import time

    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL, 0, 0, 0)  # 1 = PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(0.5)
        os._exit(1)

    if os.getppid() != parent:
        os._exit(1)
    threading.Thread(target=watch, daemon=True, name="die-with-parent").start()
