"""The indexed pattern-table store (SQLite): a damaged or hostile store is one line, exit 2, in bounded memory.

The store is read where ``cospherical check`` (and every reader) meets it; the R = 4
store's entries against its YAML are compared in ``studies/intersection/test_table.py``, which
makes both.
"""

from __future__ import annotations

import subprocess
import sys
import zlib

import pytest

from cospherical.studies.intersection import run_intersection


@pytest.fixture(scope="module")
def small_store(tmp_path_factory):
    """The R = 2 store (144 configurations), for the damaged and hostile cases below.

    Each case is refused where the reader meets it, whatever the store's size; a whole
    R = 4 store is read above, and reading 32,077 entries per case only made the runs long.
    """
    from cospherical.catalogue import shipped_catalogue
    from cospherical.formats.intersection_table import write_pattern_table
    from cospherical.studies.intersection.table import TableRun

    path = tmp_path_factory.mktemp("r2") / "r2.sqlite"
    write_pattern_table(TableRun(run_intersection(2, jobs=1)), shipped_catalogue().version, store=path)
    return path


@pytest.mark.parametrize("damage", ["truncated", "overwritten", "a page in the middle", "not a store"])
def test_a_bad_store_is_refused_with_exit_2(small_store, tmp_path, damage):
    data = bytearray(small_store.read_bytes())
    if damage == "truncated":
        data = data[: len(data) // 2]
    elif damage == "a page in the middle":  # found only when the entries are read
        middle = len(data) // 2 // 4096 * 4096
        data[middle:middle + 4096] = bytes(range(256)) * 16
    elif damage == "overwritten":  # every page after the first: the tables' pages are garbage
        data[4096:] = bytes(range(256)) * ((len(data) - 4096) // 256) + bytes((len(data) - 4096) % 256)
    else:
        data = b"SQLite format 3\x00" + b"\x00" * 200
    path = tmp_path / "bad.sqlite"
    path.write_bytes(bytes(data))
    result = subprocess.run([sys.executable, "-m", "cospherical", "check", str(path)], capture_output=True, text=True)
    assert result.returncode == 2, result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and "bad.sqlite" in result.stderr


def _bomb(connection):
    # 1 MB (just under the store's 1 MiB bound on an entry as stored) that unpacks into a gigabyte: a valid
    # zlib stream with the store's dictionary, '{' and 1 GiB of spaces. After a full flush the compressor's
    # history is empty, so each further 16 MiB of spaces compresses to the same bytes: they are repeated
    # rather than compressed 64 times (3 CPU-s), and the checksum of the whole is put in the trailer.
    (dictionary,) = connection.execute("SELECT data FROM dictionary").fetchone()
    packer = zlib.compressobj(9, zdict=dictionary)
    spaces = b" " * (1 << 24)
    head = packer.compress(b"{") + packer.compress(spaces) + packer.flush(zlib.Z_FULL_FLUSH)
    again = packer.compress(spaces) + packer.flush(zlib.Z_FULL_FLUSH)
    checksum = zlib.adler32(b"{")
    for _ in range(64):
        checksum = zlib.adler32(spaces, checksum)
    blob = head + again * 63 + packer.flush()[:-4] + checksum.to_bytes(4, "big")
    assert len(blob) < 1 << 20
    connection.execute("UPDATE entries SET entry = ? WHERE code = (SELECT min(code) FROM entries)", (blob,))


@pytest.mark.parametrize("edit, needle", [
    (_bomb, "unpacks to over"),
    (lambda c: c.execute("UPDATE meta SET value = ? WHERE key = 'header'", ("[" * 30000 + "]" * 30000,)), "nest"),
    (lambda c: c.execute("UPDATE meta SET value = ? WHERE key = 'header'", ("{}" + " " * (1 << 20),)), "header"),
    (lambda c: c.execute("UPDATE dictionary SET data = ?", (b"x" * (1 << 24),)), "dictionary"),
    (lambda c: c.execute("UPDATE meta SET value = '-5' WHERE key = 'count'"), "count"),
    (lambda c: c.execute("UPDATE meta SET value = '5' WHERE key = 'count'"), "count says"),  # found when opened
    (lambda c: c.execute("INSERT INTO dictionary VALUES (x'00')"), "dictionary"),
    (lambda c: c.executescript("INSERT INTO entries VALUES ('000000000048\n', x'00'); "
                               "UPDATE meta SET value = value + 1 WHERE key = 'count'"), "not a configuration code"),
    (lambda c: c.execute("PRAGMA journal_mode = WAL"), "WAL"),
    # a view that never ends, where the entries should be
    (lambda c: c.executescript("DROP TABLE entries; CREATE VIEW entries(code, entry) AS WITH RECURSIVE r(n) AS "
                               "(SELECT 1 UNION ALL SELECT n + 1 FROM r) SELECT printf('%012x', n), x'00' FROM r"),
     "tables"),
])
def test_a_hostile_store_is_refused_in_bounded_memory(small_store, tmp_path, edit, needle):
    import resource
    import sqlite3

    path = tmp_path / "hostile.sqlite"
    path.write_bytes(small_store.read_bytes())
    connection = sqlite3.connect(path)
    edit(connection)
    connection.commit()
    connection.close()
    # in 1 GiB of address space: reading what the store says it holds would not fit
    result = subprocess.run([sys.executable, "-m", "cospherical", "check", str(path)], capture_output=True, text=True,
                            preexec_fn=lambda: resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30)))
    assert result.returncode == 2, result.stderr
    (line,) = result.stderr.strip().splitlines()
    assert "hostile.sqlite" in line and needle in line, line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["hostile.sqlite"]  # nothing written beside it
