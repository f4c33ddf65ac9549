"""Zips deflated in threads (``formats/deflated.py``): read back by zipfile and numpy, equal to zipfile's own bytes
where a member is one block, and the same bytes whatever the threads do."""

from __future__ import annotations

import io
import random
import time
import zipfile
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cospherical.formats import deflated
from cospherical.formats.deflated import write_zip


def _zipped(members, workers=2, **options) -> bytes:
    """The zip written with ``workers`` threads (0: none, every block deflated in the caller's thread)."""
    buffer = io.BytesIO()
    if not workers:
        write_zip(buffer, members, 1, deflated.InlinePool(), **options)
        return buffer.getvalue()
    with ThreadPoolExecutor(workers) as pool:
        write_zip(buffer, members, 1, pool, **options)
    return buffer.getvalue()


def _read(data: bytes) -> dict[str, bytes]:
    with zipfile.ZipFile(io.BytesIO(data)) as archive:
        assert archive.testzip() is None  # every member's CRC
        assert {(i.date_time, i.external_attr >> 16, i.compress_type, i.create_system) for i in archive.infolist()} \
            == {((1980, 1, 1, 0, 0, 0), 0o644, zipfile.ZIP_DEFLATED, 3)}
        return {info.filename: archive.read(info) for info in archive.infolist()}


def _members(sizes: list[int], seed: int) -> list[tuple[str, tuple[bytes, memoryview]]]:
    """Members of a short header and an array's bytes, compressible and not (a ramp, then noise)."""
    generator = np.random.default_rng(seed)
    members = []
    for k, size in enumerate(sizes):
        data = np.concatenate([np.arange(size // 2, dtype=np.uint8),
                               generator.integers(0, 256, size - size // 2, dtype=np.uint8)])
        members.append((f"m{k}.npy", (bytes([k]) * (k % 3), data.data)))
    return members


def test_members_of_one_block_are_zipfiles_own_bytes():
    """zipfile on Linux (made by Unix), dated 1980-01-01 by default, its members given part by part."""
    members = _members([0, 5, 1000, 70_000], seed=1)
    theirs = io.BytesIO()  # as this project wrote dual.npz before: a member named takes the archive's level
    with zipfile.ZipFile(theirs, "w", zipfile.ZIP_DEFLATED, compresslevel=1) as archive:
        for name, parts in members:
            with archive.open(name, "w") as stream:  # part by part, as the writer hands them to zlib
                for part in parts:
                    stream.write(part)
            archive.getinfo(name).external_attr = 0o644 << 16
    assert _zipped(members) == theirs.getvalue()


@settings(max_examples=25, deadline=None)
@given(st.lists(st.integers(0, 700), min_size=1, max_size=6), st.integers(0, 4))
def test_blocks_join_into_each_members_bytes_whatever_the_threads(sizes, workers):
    members = _members(sizes, seed=len(sizes))
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(deflated, "BLOCK", 64)  # members of many blocks, parts cut across block bounds
        data = _zipped(members, workers)
        assert _read(data) == {name: b"".join(parts) for name, parts in members}
        assert _zipped(members, 1) == data == _zipped(members, 0)


def test_threads_finishing_in_any_order_write_the_same_bytes(monkeypatch):
    monkeypatch.setattr(deflated, "BLOCK", 256)
    members = _members([3000, 10, 4000], seed=2)
    first = _zipped(members, 1)
    deflate, shuffled = deflated._deflate, random.Random(5)

    def late(*arguments):
        time.sleep(shuffled.random() / 500)  # blocks finish out of their order
        return deflate(*arguments)

    monkeypatch.setattr(deflated, "_deflate", late)
    assert _zipped(members, 4) == first


def test_zip64_fields_where_zipfile_puts_them(monkeypatch):
    """Past the bound (lowered to 100 bytes here: 2**31 - 1 in use) sizes and offsets go to zip64 fields and the
    end record is zip64's; zipfile and numpy read them."""
    monkeypatch.setattr(deflated, "BLOCK", 100)
    arrays = {"a": np.arange(200, dtype=np.int64), "b": np.zeros((3, 2)), "c": np.arange(5, dtype=np.uint8)}
    members = []
    for name, array in arrays.items():
        header = io.BytesIO()
        np.lib.format.write_array_header_1_0(header, np.lib.format.header_data_from_array_1_0(array))
        members.append((f"{name}.npy", (header.getvalue(), array.data)))
    data = _zipped(members, zip64_limit=100)
    assert b"PK\x06\x06" in data and b"PK\x06\x07" in data  # the zip64 end record and its locator
    with zipfile.ZipFile(io.BytesIO(data)) as archive:
        assert archive.testzip() is None
        assert [i.file_size for i in archive.infolist()] == [len(b"".join(parts)) for _, parts in members]
    loaded = np.load(io.BytesIO(data))
    assert all(np.array_equal(loaded[name], array) for name, array in arrays.items())
