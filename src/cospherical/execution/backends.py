"""Where work units run (a study's chunks, a mesh's parts): in this process, a local process pool, or Dask."""

from __future__ import annotations

from contextlib import contextmanager
from types import FrameType
from typing import Any, Callable, Hashable, Iterator, Mapping, TypedDict, TypeVar

from ..errors import InputError, UsageError

__all__ = ["Backend", "check_backend", "completed"]

_Key = TypeVar("_Key", bound=Hashable)  # a task's key: what its result comes back with


class Backend(TypedDict):
    """Where work runs: :func:`completed`'s keywords, kept together by a caller that runs several stages."""

    jobs: int
    scheduler: str | None
    dask_workers: int | None


# Local worker processes (--jobs, --dask-workers) at most: each one starts a Python with numpy
# (a third of a CPU-second and tens of MB), so 100,000 of them ran for minutes before anything
# was refused; no machine this runs on has more cores than this.
MAX_WORKERS = 256
# --scheduler-timeout at most (seconds): dask turns it into a timedelta, which inf or 1e308 is not
# (inf was a KeyError traceback, 1e308 a run that never ended).
_MAX_TIMEOUT = 86400.0


def check_backend(prog: str, scheduler: str | None, dask_workers: int | None, timeout: float,
                  jobs: int | None = None) -> None:
    """Refuse a bad choice of backend with one line (``prog``: the command, for the message); set the timeout.

    ``scheduler`` must look like ``tcp://HOST:PORT``, ``dask_workers`` and ``jobs`` be from 1 to
    :data:`MAX_WORKERS`, not both Dask options given, and dask.distributed installed.
    """
    import math
    import re

    if scheduler and dask_workers:
        raise UsageError(f"{prog}: error: give --scheduler or --dask-workers, not both")
    for option, count in (("--dask-workers", dask_workers), ("--jobs", jobs)):
        if count is not None and not 1 <= count <= MAX_WORKERS:
            raise UsageError(f"{prog}: error: {option} {count}: must be an integer from 1 to {MAX_WORKERS}")
    if scheduler or dask_workers:
        from importlib.util import find_spec

        if find_spec("distributed") is None:
            raise UsageError(f"{prog}: error: the Dask backend needs dask.distributed: pip install 'cospherical[dask]'")
    if scheduler:
        if not re.fullmatch(r"(tcp|tls|ucx)://[A-Za-z0-9._\[\]:-]+", scheduler):
            raise UsageError(f"{prog}: error: --scheduler {scheduler!r}: give tcp://HOST:PORT")
        if not (math.isfinite(timeout) and 0 < timeout <= _MAX_TIMEOUT):
            raise UsageError(f"{prog}: error: --scheduler-timeout {timeout}: must be more than 0 seconds and at "
                             f"most {_MAX_TIMEOUT:,.0f}")
        import dask

        dask.config.set({"distributed.comm.timeouts.connect": f"{timeout}s"})


def completed(function: Callable[..., Any], tasks: Mapping[_Key, tuple[Any, ...]], jobs: int = 1, scheduler: str | None = None,
              dask_workers: int | None = None, common: tuple[Any, ...] = ()) -> Iterator[tuple[_Key, Any]]:
    """Yield ``(key, function(*args))`` for every task, in the order they finish, on the chosen backend.

    Parameters
    ----------
    function : callable
        A module-level function (workers import it by name).
    tasks : dict
        Key -> the arguments of one call.
    jobs : int
        Local worker processes; 1 runs in this process.
    scheduler : str, optional
        The address of a running Dask scheduler (``tcp://SCHEDULER:8786``).
    dask_workers : int, optional
        Start a local Dask cluster of that many processes instead.
    common : tuple
        Arguments after each task's own, the same for every call: on Dask they are sent
        to the workers once (scattered), not once per task in the task graph.

    Examples
    --------
    >>> sorted(completed(pow, {"a": (2, 3), "b": (3, 2)}))
    [('a', 8), ('b', 9)]
    """
    if scheduler or dask_workers:
        yield from _dask_completed(function, tasks, scheduler, dask_workers, common)
    elif jobs <= 1:
        for key, args in tasks.items():
            yield key, function(*args, *common)
    else:
        from concurrent.futures import FIRST_COMPLETED, wait

        from .pool import process_pool

        with process_pool(jobs) as pool:  # left by an error, Ctrl-C or SIGTERM: the workers are stopped at once
            pending = {pool.submit(function, *args, *common): key for key, args in tasks.items()}
            while pending:
                # not as_completed, which keeps every future, and so every result, to the end
                done, _ = wait(pending, return_when=FIRST_COMPLETED)
                for future in done:
                    yield pending.pop(future), future.result()


def _dask_completed(function: Callable[..., Any], tasks: Mapping[_Key, tuple[Any, ...]], scheduler: str | None,
                    dask_workers: int | None, common: tuple[Any, ...] = ()) -> Iterator[tuple[_Key, Any]]:
    """:func:`completed` on Dask: a running scheduler, or a local cluster whose scratch space
    (its lock files included) is a private temporary folder, removed at the end however the run ends."""
    import logging
    import shutil
    import signal
    import tempfile
    import warnings

    # Imported here: dask is an optional extra, and a heavy import the other backends never need.
    import dask
    from dask.distributed import Client, LocalCluster, as_completed

    from .pool import register_stop, unregister_stop

    scratch = None if scheduler else tempfile.mkdtemp(prefix="cospherical-dask-")
    cluster = client = None
    # distributed's own log quiet for the run: a cluster shut down by Ctrl-C logs closed comms with
    # their tracebacks, some from its event loop's thread after close() has returned (and after the
    # cluster has put back the level its silence_logs changed). Put back only after a run that ended
    # well: after an error or an interrupt those late lines would follow the command's one line.
    # (its handlers', as silence_logs does: some of its loggers have levels of their own)
    handlers = {handler: handler.level for handler in logging.getLogger("distributed").handlers}
    for handler in handlers:
        handler.setLevel(logging.CRITICAL)
    ended_well = False
    try:
        if scratch is not None:
            # Ctrl-C reaches the whole process group, and a worker caught by it while it starts
            # prints a traceback. Workers are forked from a fork server started with SIGINT ignored
            # (for the few milliseconds of its spawn), so they ignore it too, and only this
            # process, which stops them, sees it. silence_logs: a cluster shut down by Ctrl-C logs
            # lost heartbeats as tracebacks; a task's own error still reaches us through its future.
            from multiprocessing import forkserver

            previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
            try:
                forkserver.ensure_running()
            finally:
                signal.signal(signal.SIGINT, previous)
            settings = {"temporary-directory": scratch,  # the scheduler's scratch space too
                        "distributed.worker.multiprocessing-method": "forkserver"}
            # warnings ignored: the scheduler's HTTP server, on a port another cluster holds, moves to
            # a free one and says so in four lines on stderr, where the command promises one line
            with dask.config.set(settings), _interrupt_deferred(), warnings.catch_warnings():
                warnings.simplefilter("ignore")
                cluster = LocalCluster(n_workers=dask_workers, threads_per_worker=1, processes=True,
                                       dashboard_address=None, local_directory=scratch,
                                       silence_logs=logging.CRITICAL)
        if scheduler:
            _handshake(scheduler)
        try:  # the connect timeout is dask's distributed.comm.timeouts.connect (--scheduler-timeout)
            client = Client(scheduler or cluster)
        except (OSError, TimeoutError, ValueError, TypeError) as error:
            raise InputError(f"Dask scheduler {scheduler}: cannot connect: "
                             f"{str(error).splitlines()[0] if str(error) else type(error).__name__}") from None
        register_stop(id(client), lambda: _stop_dask(client, cluster))
        shared = client.scatter(list(common), broadcast=True) if common else []
        futures = {client.submit(function, *args, *shared, pure=False): key for key, args in tasks.items()}
        for future in as_completed(futures):
            # dropped once yielded: a finished future keeps its result (chunks of a
            # pattern table hold megabytes each)
            yield futures.pop(future), future.result()
        ended_well = True
    except BaseException:
        _kill_workers(cluster)  # an error, Ctrl-C or SIGTERM: no wait for the chunks still running
        raise
    finally:
        unregister_stop(id(client))
        _close_dask(client, cluster)
        if scratch is not None:
            shutil.rmtree(scratch, ignore_errors=True)
        if ended_well:
            for handler, level in handlers.items():
                handler.setLevel(level)


def _handshake(scheduler: str) -> None:
    """Connect to ``scheduler`` once and read its handshake, within --scheduler-timeout; else one line.

    dask's Client bounds the TCP connect but not the wait for an answer: a port on
    127.0.0.1 that accepted and said nothing kept the command waiting for good (over
    120 s with --scheduler-timeout 3); one that sent garbage ended in "out of memory".
    """
    import asyncio

    import dask
    from dask.utils import parse_timedelta
    from distributed.comm import connect

    timeout = parse_timedelta(dask.config.get("distributed.comm.timeouts.connect"), "s")
    _listening(scheduler, timeout)

    async def handshake() -> None:
        comm = await asyncio.wait_for(connect(scheduler, timeout=timeout), timeout)
        await comm.close()

    try:
        asyncio.run(handshake())
    except (asyncio.TimeoutError, TimeoutError):
        raise InputError(f"Dask scheduler {scheduler}: cannot connect: no answer within {timeout:g} s") from None
    except Exception as error:  # refused, unreachable, or not a Dask scheduler's answer (MemoryError included)
        text = str(error).splitlines()[0] if str(error) else type(error).__name__
        raise InputError(f"Dask scheduler {scheduler}: cannot connect: {text}") from None


def _listening(scheduler: str, timeout: float) -> None:
    """Refuse at once, with one line, a TCP or TLS scheduler address where nothing can be reached.

    dask's ``connect`` retries a refused connection or an unknown host name until its
    timeout: a port where nothing listens, or a mistyped host, cost the whole 30 s of the
    default ``--scheduler-timeout`` before the command said so. One plain TCP connect tells
    at once (the kernel refuses a closed port; a name that does not resolve fails in the
    lookup), and still waits up to the timeout for a host that does not answer at all.
    """
    import socket
    from urllib.parse import urlsplit

    address = urlsplit(scheduler)
    if address.scheme not in ("tcp", "tls"):  # ucx:// is not TCP: dask alone decides
        return
    try:
        host, port = address.hostname, address.port
    except ValueError:  # a port that is not a number, or out of range
        raise InputError(f"Dask scheduler {scheduler}: cannot connect: the port is not a number from 0 to "
                         "65535") from None
    if not host or port is None:
        raise InputError(f"Dask scheduler {scheduler}: cannot connect: give tcp://HOST:PORT")
    named = address.netloc.rpartition(":")[0].strip("[]")  # the host as given (hostname is lower-cased)
    try:
        socket.create_connection((host, port), timeout=timeout).close()
    except socket.gaierror:
        raise InputError(f"Dask scheduler {scheduler}: cannot connect: host {named!r} not found") from None
    except ConnectionRefusedError:
        raise InputError(f"Dask scheduler {scheduler}: cannot connect: nothing listens on port {port} "
                         f"of {named}") from None
    except TimeoutError:
        raise InputError(f"Dask scheduler {scheduler}: cannot connect: no answer within {timeout:g} s") from None
    except OSError as error:  # no route to the host, network unreachable
        raise InputError(f"Dask scheduler {scheduler}: cannot connect: {error.strerror or error}") from None


@contextmanager
def _interrupt_deferred() -> Iterator[None]:
    """Hold a Ctrl-C or SIGTERM back until the block has ended, then act on it as the command would have.

    A cluster half made when the signal arrived could not be closed: its workers went on
    starting and made their scratch space again (with its lock files) after the command had
    removed it, so SIGTERM left a /tmp/cospherical-dask-* folder behind.
    """
    import signal

    held: list[int] = []
    previous: dict[int, Callable[[int, FrameType | None], Any] | int | None] = {}
    try:
        for signum in (signal.SIGINT, signal.SIGTERM):
            previous[signum] = signal.signal(signum, lambda signum, frame: held.append(signum))
    except ValueError:  # not the main thread: signals are not ours to handle
        yield
        return
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
    if held:
        handler = previous[held[0]]
        if held[0] == signal.SIGINT and not callable(handler):
            raise KeyboardInterrupt
        if callable(handler):
            handler(held[0], None)  # the command's own: KeyboardInterrupt, or SystemExit(143) for SIGTERM
        else:
            signal.raise_signal(held[0])  # the default action, as if it had not been held


def _stop_dask(client: Any, cluster: Any) -> None:
    """Stop a run on Dask now (Ctrl-C, SIGTERM): its local workers killed, then client and cluster closed."""
    _kill_workers(cluster)
    _close_dask(client, cluster)


def _kill_workers(cluster: Any) -> None:
    """Kill the worker processes of a local cluster, whose nannies would wait seconds for running tasks."""
    import os
    import signal

    from distributed.core import Status

    for nanny in list(getattr(cluster, "workers", {}).values()):
        pid = getattr(nanny, "pid", None)
        nanny.status = Status.closing_gracefully  # the nanny then closes, instead of starting the worker again
        if pid:
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass


def _close_dask(client: Any, cluster: Any) -> None:
    """Close the client and the local cluster without a word, even when a second Ctrl-C arrives meanwhile.

    Once closed they are also no longer in dask's own exit handlers, which would
    otherwise try again at interpreter exit and print a traceback.
    """
    for closable in (client, cluster):
        if closable is None:
            continue
        for _ in range(3):
            try:
                closable.close(timeout=5)
                break
            except KeyboardInterrupt:
                continue
            except Exception:
                break
