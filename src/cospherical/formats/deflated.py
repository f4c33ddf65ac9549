"""Zip files of deflated members, compressed in threads: the same bytes whatever the threads do.

A large ``.npz`` spends most of its writing time in deflate, one core at a time when
written through :mod:`zipfile` (a member's data goes through one compressor).  Here
every member is cut into blocks of ``BLOCK`` bytes, each block deflated on its own
(raw deflate, ended by a sync flush, the member's last block by the stream's end: the
blocks joined are one valid deflate stream, as pigz makes them) by a pool of threads;
zlib and the CRC release the GIL, so the blocks run on every core.  The blocks'
bounds depend only on the members' sizes and each block's bytes only on its data, so
the file is the same byte for byte whatever the threads' timing; the blocks are
written in order as they come, a window of them in flight (the whole compressed
payload is never held).  A block of 1 MiB costs about 0.03 % in size against one
stream per member.

The container is the zip format as :mod:`zipfile` writes it with sizes known before
the data (no data descriptors): a local header per member, the central directory, the
end record; zip64 fields exactly where :mod:`zipfile` puts them (a size or offset
past ``2**31 - 1``, more than 65,535 members); every member dated 1980-01-01 00:00
(no clock) with mode ``rw-r--r--`` from a Unix system, whatever the machine.
"""

from __future__ import annotations

import os
import struct
import zlib
from collections import deque
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any, BinaryIO, Callable, Generic, Iterator, Sequence, TypeVar, Union

if TYPE_CHECKING:
    from concurrent.futures import Executor, Future

__all__ = ["BLOCK", "SERIAL_BYTES", "ZIP64_LIMIT", "InlinePool", "deflate_workers", "deflating", "in_threads", "write_zip"]

BLOCK = 1 << 20
ZIP64_LIMIT = (1 << 31) - 1  # zipfile's: sizes and offsets past it are written as zip64 fields
_MEMBER_LIMIT = (1 << 16) - 1  # more members: zip64 end records
_VERSION, _ZIP64_VERSION = 20, 45  # the zip version needed: deflate, and deflate with zip64 fields
_UNIX = 3  # the "made by" system: Unix, so that the mode below is read as one
_MODE = 0o644 << 16  # rw-r--r-- when unpacked
_DATE, _TIME = (1980 - 1980) << 9 | 1 << 5 | 1, 0  # 1980-01-01 00:00:00, the earliest a zip can say
_DEFLATED = 8
_MAX_WORKERS = 8  # deflate's threads at most: past that the writing of the file itself dominates

# Payloads up to this many bytes are deflated in the caller's thread: below it, starting threads, handing them the
# blocks and importing concurrent.futures (5 ms: logging comes with it) cost more CPU than the threads save wall
# time.  The README's sphere trees, `mesh --dual` serial against threaded (11 pairs): level 4 (0.7 MB of members)
# and level 5 (2.6 MB) -5 % CPU-s at the same wall time; level 6 (11 MB) keeps its threads (serial: the same
# CPU-s, +8 % wall)
SERIAL_BYTES = 4 << 20

Buffer = Union[bytes, memoryview]
T = TypeVar("T")


class _Done(Generic[T]):
    """A call's result, computed already: what :meth:`InlinePool.submit` gives for a future."""

    __slots__ = ("value",)

    def __init__(self, value: T) -> None:
        self.value = value

    def result(self) -> T:
        return self.value


class InlinePool:
    """The part of an executor :func:`write_zip` uses, run in the caller's thread: each call at once, when
    submitted (the same bytes as any pool: only the order of the work differs)."""

    def submit(self, fn: Callable[..., T], /, *args: Any) -> _Done[T]:
        return _Done(fn(*args))


def in_threads(nbytes: int) -> bool:
    """Whether a payload of ``nbytes`` is worth deflating in threads (see ``SERIAL_BYTES``)."""
    return nbytes > SERIAL_BYTES


def deflate_workers() -> int:
    """Threads worth deflating with: the processors this process may run on (at most 8)."""
    try:
        count = len(os.sched_getaffinity(0))
    except AttributeError:  # not on every system
        count = os.cpu_count() or 1
    return max(1, min(count, _MAX_WORKERS))


@contextmanager
def deflating(nbytes: int, pool: Executor | InlinePool | None = None, name: str = "deflate",
              most: int | None = None) -> Iterator[Executor | InlinePool]:
    """What deflates a payload of ``nbytes``: ``pool`` when the caller gives one; else, for a payload worth them
    (:func:`in_threads`), :func:`deflate_workers` threads (at most ``most``) named ``name``, shut down on leaving;
    else the caller's thread (:class:`InlinePool`).  The same bytes with any."""
    if pool is not None:
        yield pool
    elif not in_threads(nbytes):
        yield InlinePool()
    else:
        from concurrent.futures import ThreadPoolExecutor  # with logging: ~5 ms, paid only where threads run

        workers = deflate_workers() if most is None else min(deflate_workers(), most)
        with ThreadPoolExecutor(workers, thread_name_prefix=name) as threads:
            yield threads


def _blocks(parts: Sequence[Buffer]) -> Iterator[tuple[list[memoryview], bool]]:
    """A member's bytes (its parts one after the other) as blocks of ``BLOCK`` bytes (the last one shorter),
    each a list of views into the parts (no copy), with whether it is the member's last."""
    views = [memoryview(part).cast("B") for part in parts]
    total = sum(view.nbytes for view in views)
    block: list[memoryview] = []
    filled, done = 0, 0
    for view in views:
        at = 0
        while at < view.nbytes:
            take = min(BLOCK - filled, view.nbytes - at)
            block.append(view[at:at + take])
            at += take
            filled += take
            done += take
            if filled == BLOCK and done < total:
                yield block, False
                block, filled = [], 0
    yield block, True


def _deflate(pieces: list[memoryview], level: int, last: bool) -> bytes:
    """One block, raw deflate: ended by a sync flush (byte-aligned, not final) or, the member's last, by the
    stream's end."""
    compressor = zlib.compressobj(level, zlib.DEFLATED, -15)
    out = [compressor.compress(piece) for piece in pieces]
    out.append(compressor.flush(zlib.Z_FINISH if last else zlib.Z_SYNC_FLUSH))
    return b"".join(out)


def _crc32(parts: Sequence[Buffer]) -> int:
    crc = 0
    for part in parts:
        crc = zlib.crc32(part, crc)
    return crc


def write_zip(handle: BinaryIO, members: Sequence[tuple[str, Sequence[Buffer]]], level: int,
              pool: Executor | InlinePool, zip64_limit: int = ZIP64_LIMIT) -> None:
    """Write a zip of ``members`` (name, then its bytes as parts to be joined) to ``handle``, in that order,
    each deflated at ``level`` in blocks on ``pool``'s threads (see the module).

    The parts are read while the call runs and must not change.  ``zip64_limit`` is :mod:`zipfile`'s bound
    (lower only to test the zip64 fields on small files).
    """
    names = [name.encode("ascii") for name, _ in members]  # no flag for UTF-8 names: ASCII only
    crcs = [pool.submit(_crc32, parts) for _, parts in members]
    blocks = ((m, pieces, last) for m, (_, parts) in enumerate(members) for pieces, last in _blocks(parts))
    pending: deque[tuple[int, Future[bytes] | _Done[bytes]]] = deque()
    window = 4 * deflate_workers()  # blocks in flight: every thread busy, a few blocks of output held

    def top_up() -> None:
        for m, pieces, last in blocks:
            pending.append((m, pool.submit(_deflate, pieces, level, last)))
            if len(pending) >= window:
                return

    top_up()
    directory = []
    offset = handle.tell()  # where the next record starts: offsets in a zip count from the file's start
    for m, (_, parts) in enumerate(members):
        data = []
        while pending and pending[0][0] == m:
            data.append(pending.popleft()[1].result())
            top_up()
        size = sum(memoryview(part).nbytes for part in parts)
        compressed = sum(len(block) for block in data)
        crc = crcs[m].result()
        zip64 = size > zip64_limit or compressed > zip64_limit
        extra = struct.pack("<HHQQ", 1, 16, size, compressed) if zip64 else b""
        version = _ZIP64_VERSION if zip64 else _VERSION
        handle.write(struct.pack("<4s2B4HL2L2H", b"PK\x03\x04", version, 0, 0, _DEFLATED, _TIME, _DATE, crc,
                                 0xFFFFFFFF if zip64 else compressed, 0xFFFFFFFF if zip64 else size,
                                 len(names[m]), len(extra)))
        handle.write(names[m])
        handle.write(extra)
        for block in data:
            handle.write(block)
        directory.append((offset, size, compressed, crc))
        offset += 30 + len(names[m]) + len(extra) + compressed
    directory_start = offset
    for name, (at, size, compressed, crc) in zip(names, directory):
        fields = ([size, compressed] if size > zip64_limit or compressed > zip64_limit else []) + (
            [at] if at > zip64_limit else [])
        extra = struct.pack("<HH" + "Q" * len(fields), 1, 8 * len(fields), *fields) if fields else b""
        version = _ZIP64_VERSION if fields else _VERSION
        wide = size > zip64_limit or compressed > zip64_limit
        handle.write(struct.pack("<4s4B4HL2L5H2L", b"PK\x01\x02", version, _UNIX, version, 0, 0, _DEFLATED, _TIME,
                                 _DATE, crc, 0xFFFFFFFF if wide else compressed, 0xFFFFFFFF if wide else size,
                                 len(name), len(extra), 0, 0, 0, _MODE, 0xFFFFFFFF if at > zip64_limit else at))
        handle.write(name)
        handle.write(extra)
        offset += 46 + len(name) + len(extra)
    count, directory_size = len(members), offset - directory_start
    if count > _MEMBER_LIMIT or directory_start > zip64_limit or directory_size > zip64_limit:
        handle.write(struct.pack("<4sQ2H2L4Q", b"PK\x06\x06", 44, _ZIP64_VERSION, _ZIP64_VERSION, 0, 0, count,
                                 count, directory_size, directory_start))
        handle.write(struct.pack("<4sLQL", b"PK\x06\x07", 0, offset, 1))
        count, directory_size, directory_start = (min(count, 0xFFFF), min(directory_size, 0xFFFFFFFF),
                                                   min(directory_start, 0xFFFFFFFF))
    handle.write(struct.pack("<4s4H2LH", b"PK\x05\x06", 0, 0, count, count, directory_size, directory_start, 0))
