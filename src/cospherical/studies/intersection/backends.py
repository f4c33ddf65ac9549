"""Where the work units of the intersection study run: in this process, a local process pool, or Dask."""

from __future__ import annotations

from typing import Any, Callable, Hashable, Iterator

from ...errors import InputError

__all__ = ["completed"]


def completed(function: Callable, tasks: dict[Hashable, tuple], jobs: int = 1, scheduler: str | None = None,
              dask_workers: int | None = None) -> Iterator[tuple[Hashable, Any]]:
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

    Examples
    --------
    >>> sorted(completed(pow, {"a": (2, 3), "b": (3, 2)}))
    [('a', 8), ('b', 9)]
    """
    if scheduler or dask_workers:
        # Imported here: dask is an optional extra, and a heavy import the other backends never need.
        from dask.distributed import Client, LocalCluster, as_completed

        cluster = None if scheduler else LocalCluster(n_workers=dask_workers, threads_per_worker=1,
                                                      processes=True, dashboard_address=None)
        try:  # the connect timeout is dask's distributed.comm.timeouts.connect (--scheduler-timeout)
            client = Client(scheduler or cluster)
        except (OSError, TimeoutError, ValueError, TypeError) as error:
            raise InputError(f"Dask scheduler {scheduler}: cannot connect: "
                             f"{str(error).splitlines()[0] if str(error) else type(error).__name__}") from None
        try:
            futures = {client.submit(function, *args, pure=False): key for key, args in tasks.items()}
            for future in as_completed(futures):
                # dropped once yielded: a finished future keeps its result (chunks of a
                # pattern table hold megabytes each)
                yield futures.pop(future), future.result()
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    elif jobs <= 1:
        for key, args in tasks.items():
            yield key, function(*args)
    else:
        from concurrent.futures import FIRST_COMPLETED, wait

        from ..pool import process_pool

        pool = process_pool(jobs)
        try:
            pending = {pool.submit(function, *args): key for key, args in tasks.items()}
            while pending:
                # not as_completed, which keeps every future, and so every result, to the end
                done, _ = wait(pending, return_when=FIRST_COMPLETED)
                for future in done:
                    yield pending.pop(future), future.result()
        finally:
            pool.shutdown(wait=True, cancel_futures=True)
