"""Local process pools whose workers never outlive the command, and stop at once when it is stopped."""

from __future__ import annotations

import os
import signal
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from types import TracebackType
from typing import Any, Literal

__all__ = ["die_with_parent", "process_pool", "register_stop", "stop_all", "unregister_stop"]

# What stops each running set of workers (pools, local Dask clusters), by key.
_running: dict[int, Callable[[], None]] = {}


def register_stop(key: int, stop: Callable[[], None]) -> None:
    """Remember how to stop a running set of workers, for :func:`stop_all`."""
    _running[key] = stop


def unregister_stop(key: int) -> None:
    _running.pop(key, None)


def stop_all() -> None:
    """Stop every running set of workers now (the command calls it on Ctrl-C and SIGTERM).

    The ``with`` blocks and generators that own the workers stop them when they
    are left, but an interrupt that arrives while their caller is elsewhere (a
    generator of results held by a loop that is writing a checkpoint) leaves
    them open until exit, where the interpreter would join the workers and so
    wait for the chunks they are running.
    """
    for key, stop in list(_running.items()):
        try:
            stop()
        except Exception:  # stopping is best effort: never a second error over the first
            pass
        unregister_stop(key)


class _Pool(ProcessPoolExecutor):
    """A process pool that, left by an error, Ctrl-C or SIGTERM, stops at once instead of waiting."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        register_stop(id(self), self.stop)

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        unregister_stop(id(self))
        super().shutdown(wait=wait, cancel_futures=cancel_futures)

    def __exit__(self, kind: type[BaseException] | None, value: BaseException | None,
                 traceback: TracebackType | None) -> Literal[False]:
        if kind is None:
            self.shutdown(wait=True)
        else:
            self.stop()
        return False

    def stop(self) -> None:
        """Stop now: queued calls cancelled, running ones killed with their workers.

        ``shutdown(cancel_futures=True)`` alone still waits for the calls already
        running (minutes for a chunk of the R = 8 table); a command that was
        interrupted or terminated must end now.
        """
        workers = list((getattr(self, "_processes", None) or {}).values())
        manager = getattr(self, "_executor_manager_thread", None)
        for worker in workers:  # computation only, nothing to clean up: SIGKILL, not a request to stop
            try:
                worker.kill()
            except (OSError, AttributeError):
                pass
        self.shutdown(wait=False, cancel_futures=True)
        for worker in workers:
            worker.join(timeout=5)
        # The pool's management thread sees its workers die and closes its wake-up pipe. Python 3.11's exit
        # wakes every such thread through that pipe without a lock: a thread still closing it then is an
        # "Exception ignored ... Bad file descriptor" printed after the command's last line. It ends at once.
        if manager is not None:
            manager.join(timeout=5)


def process_pool(jobs: int) -> ProcessPoolExecutor:
    """A pool of ``jobs`` worker processes that end when this process ends, even by SIGKILL, and
    that a ``with`` block left by an exception stops at once."""
    return _Pool(max_workers=jobs, initializer=die_with_parent, initargs=(os.getpid(),))


def die_with_parent(parent: int) -> None:
    """Make a pool worker end when the command that started it ends, even by SIGKILL.

    The kernel sends SIGKILL to the worker when its parent dies (Linux
    ``PR_SET_PDEATHSIG``); where that is not available, or the parent died
    before it was set, a watchdog thread sees the parent change and exits.
    """
    import ctypes
    import threading
    import time

    # Ctrl-C reaches the whole process group: the command handles it and stops the
    # workers; a worker's own KeyboardInterrupt would only print a traceback.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # not the command's handler, inherited by fork

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
