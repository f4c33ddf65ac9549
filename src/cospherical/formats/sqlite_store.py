"""Indexed pattern tables: one SQLite file beside the YAML, for tables too big to read whole.

A pattern table at R >= 4 holds hundreds of thousands of configurations (millions at
R = 16).  Its YAML stays the canonical, diffable form; the store holds the same
entries, each the same JSON text as its YAML line, keyed by configuration code in an
indexed table, so a mesher looks one configuration up without reading the rest.  Each
entry is zlib-compressed on its own with a preset dictionary (kept in the store) made
of entries spread over the table: entries are short and alike, so the dictionary is
what lets each compress ten-fold and still be read alone::

    table = cospherical.load_patterns("intersection-r8-edge-patterns.sqlite")
    table.elements("000000000048")  # an orbit representative: see the header's "symmetry"

:func:`cospherical.formats.patterns.load` opens either form; ``check`` and ``diff``
read both.  A store is written atomically (a temporary file renamed into place) and
checked when opened: a file that is not a complete SQLite database of this layout
(truncated, or another file), or whose count is not its entries', raises
:class:`FormatError`.
"""

from __future__ import annotations

import json
import os
import stat
import zlib
from collections.abc import Iterable, Iterator, Mapping
from typing import TYPE_CHECKING, Any
from pathlib import Path

from ..errors import FormatError
from ..files.yamlio import atomic_path, parse_json

if TYPE_CHECKING:  # SQLite's module is imported where a store is written or opened, not to tell one
    import sqlite3

__all__ = ["MAGIC", "StoreEntries", "dictionary_of", "is_store", "open_store", "pack", "write_store"]

MAGIC = b"SQLite format 3\x00"
_LAYOUT = 1  # the store's own layout version, in its meta table
# Measured on R = 8 entries (2.7 kB each) with a dictionary of entries spread over the
# table: level 1 gives 400 bytes, 6 gives 230 (at 1.3 times level 1's time), 9 gives 215 (at 2.6).
LEVEL = 6
_DICTIONARY_SIZE = 32768  # zlib's window: a longer dictionary is not used
# The store's tables, exactly as written and as the reader requires them: a file with
# views (a recursive one never ends), triggers or other tables is not a store.
_TABLES = {
    "meta": "CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL)",
    "entries": "CREATE TABLE entries (code TEXT PRIMARY KEY, entry BLOB NOT NULL) WITHOUT ROWID",
    "dictionary": "CREATE TABLE dictionary (data BLOB NOT NULL)",
}
_SCHEMA = {*(("table", name, sql) for name, sql in _TABLES.items()), ("index", "sqlite_autoindex_meta_1", None)}
# Bounds on what a store's reader takes: far above anything written (an entry is a few kB;
# the header a few hundred bytes), far below what would exhaust memory.
MAX_ENTRY = 1 << 20
_MAX_HEADER = 1 << 16
# An entry as stored is never longer than its text (a few hundred bytes packed).  A scan reads
# a blob's length from its record header, never the blob; but a lookup by code seeks through
# the entries' b-tree, and SQLite reads every cell it compares the code with whole, overflow
# pages and all (a 900 MB entry: 935 MB and 3 CPU-s for 'mesh --patterns' to refuse it).  So
# the sizes are bounded by one scan when the store is opened (5 ms for 32,077 entries), and
# again in each query, for a file changed after it was opened.
# The same scan counts the entries: a store whose count is not its entries' is damaged, and a mesher,
# which looks a few up, would not find that out otherwise.
_SCAN = f"SELECT count(*), coalesce(max(length(entry) > {MAX_ENTRY} OR length(code) > {MAX_ENTRY}), 0) FROM entries"
# length() of a blob reads its size from the record header, but length() of a text (the code) reads
# the text whole (a 200 MB code: 221 MB to refuse the store).  SQLite's dbstat table gives each
# page's largest record payload from the cell headers, following overflow chains page by page in
# the page cache: no record is ever held whole.  Two bounded columns and a header of a few bytes.
_OVERSIZED_RECORD = f"SELECT 1 FROM dbstat WHERE name = 'entries' AND mx_payload > {2 * MAX_ENTRY + 64} LIMIT 1"
_BOUNDED_ENTRY = f"CASE WHEN length(entry) <= {MAX_ENTRY} THEN entry END"


def is_store(path: str | Path) -> bool:
    """Whether the file is a regular file beginning like an SQLite database (else it is read as YAML,
    whose reader refuses what is not a regular file: opening a FIFO here would block)."""
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):
            return False
        with open(path, "rb") as handle:
            return handle.read(len(MAGIC)) == MAGIC
    except OSError:
        return False


def dictionary_of(samples: list[str]) -> bytes:
    """The preset dictionary made of sample entry texts from all over a table."""
    return "".join(samples).encode("utf-8")[-_DICTIONARY_SIZE:]


def pack(text: str, dictionary: bytes) -> bytes:
    """One entry as the store keeps it: compressed on its own with the table's dictionary
    (workers pack their entries; :meth:`StoreEntries._text` is the inverse)."""
    packer = zlib.compressobj(LEVEL, zdict=dictionary)
    return packer.compress(text.encode("utf-8")) + packer.flush()


def write_store(path: str | Path, header: dict[str, Any], dictionary: bytes, rows: Iterable[tuple[str, bytes]]) -> None:
    """Write a store of ``header`` and ``rows`` ((code, entry packed with ``dictionary``) pairs, in
    code order, which makes the file the same bytes for the same table), atomically."""
    import sqlite3

    with atomic_path(path) as tmp:  # an empty file: SQLite makes it a new database
        connection = sqlite3.connect(tmp)
        try:
            connection.execute("PRAGMA journal_mode = OFF")
            connection.execute("PRAGMA synchronous = OFF")
            for sql in _TABLES.values():
                connection.execute(sql)
            connection.executemany("INSERT INTO meta VALUES (?, ?)",
                                   [("layout", str(_LAYOUT)), ("header", json.dumps(header, sort_keys=True))])
            connection.execute("INSERT INTO dictionary VALUES (?)", (dictionary,))
            count = 0
            batch = []
            for row in rows:
                batch.append(row)
                if len(batch) == 10_000:
                    connection.executemany("INSERT INTO entries VALUES (?, ?)", batch)
                    count += len(batch)
                    batch = []
            connection.executemany("INSERT INTO entries VALUES (?, ?)", batch)
            count += len(batch)
            connection.execute("INSERT INTO meta VALUES ('count', ?)", (str(count),))
            connection.commit()
        finally:
            connection.close()


def _complete(path: Path) -> bool:
    # The database header records its page size (bytes 16-17, 1 meaning 65536) and
    # page count (bytes 28-31): a truncated file is shorter than their product.
    with open(path, "rb") as handle:
        head = handle.read(100)
    if len(head) < 100 or not head.startswith(MAGIC):
        return False
    if head[18:20] != b"\x01\x01":  # file format versions: rollback journal, as written (WAL would write beside it)
        return False
    page_size = int.from_bytes(head[16:18], "big")
    page_size = 65536 if page_size == 1 else page_size
    pages = int.from_bytes(head[28:32], "big")
    return pages > 0 and os.path.getsize(path) >= page_size * pages


def open_store(path: str | Path) -> tuple[dict[str, Any], "StoreEntries"]:
    """The header and the entries of a store; a bad or truncated store raises :class:`FormatError`."""
    import sqlite3

    path = Path(path)
    if not _complete(path):
        raise FormatError(f"{path}: not a complete pattern-table store (truncated, in WAL mode, or not an SQLite database)")
    try:
        connection = sqlite3.connect(f"{path.resolve().as_uri()}?mode=ro", uri=True, check_same_thread=False)
        if set(connection.execute("SELECT type, name, sql FROM sqlite_master")) != _SCHEMA:
            raise ValueError("its tables are not those of a store (meta, entries, dictionary as written)")
        # Only the rows we know, and only as long as we ever write them: a hostile
        # store's gigabyte of header or dictionary is never read.
        meta = dict(connection.execute("SELECT key, value FROM meta WHERE key IN ('layout', 'header', 'count') "
                                       "AND length(value) <= ?", (_MAX_HEADER,)))
        if meta.get("layout") != str(_LAYOUT):
            raise FormatError(f"{path}: store layout {meta.get('layout')!r}, expected {_LAYOUT}")
        if "header" not in meta or "count" not in meta:
            raise ValueError(f"no header and count of at most {_MAX_HEADER} bytes")
        header = parse_json(meta["header"], f"{path}: header")
        count = int(meta["count"])
        dictionaries = connection.execute("SELECT data FROM dictionary WHERE length(data) <= ? LIMIT 2",
                                  (_DICTIONARY_SIZE,)).fetchall()
        if not isinstance(header, dict) or not 0 <= count <= 16 ** 12 or len(dictionaries) != 1 \
                or not isinstance(dictionaries[0][0], bytes):
            raise ValueError(f"its header is not a mapping, its count is not that of a table, or it has not one "
                             f"dictionary of at most {_DICTIONARY_SIZE} bytes")
        (dictionary,) = dictionaries[0]
        try:
            oversized = connection.execute(_OVERSIZED_RECORD).fetchone() is not None
        except sqlite3.OperationalError:  # an SQLite built without dbstat: the scan below reads a long code whole
            oversized = False
        if not oversized:
            rows, oversized = connection.execute(_SCAN).fetchone()
        if oversized:
            raise FormatError(f"{path}: store damaged: an entry is stored in over {MAX_ENTRY} bytes")
        if rows != count:
            raise FormatError(f"{path}: store damaged: {rows} entries, but its count says {count}")
    except FormatError:
        raise  # names the store and the place already
    except (sqlite3.Error, KeyError, ValueError, TypeError) as error:
        raise FormatError(f"{path}: not a pattern-table store: {str(error).splitlines()[0][:120]}") from None
    return header, StoreEntries(connection, count, dictionary, str(path))


class StoreEntries(Mapping[str, str]):
    """A store's configurations as code -> raw entry text (JSON), read one at a time by the index."""

    def __init__(self, connection: sqlite3.Connection, count: int, dictionary: bytes, name: str):
        self._connection = connection
        self._count = count
        self._dictionary = dictionary
        self._name = name

    def _rows(self, sql: str, arguments: tuple[object, ...] = ()) -> Iterator[tuple[Any, ...]]:
        import sqlite3

        # SQLite reads pages as rows are stepped through: a damaged page shows while
        # iterating, not only when the query starts
        try:
            yield from self._connection.execute(sql, arguments)
        except sqlite3.Error as error:
            raise FormatError(f"{self._name}: store damaged: {str(error).splitlines()[0][:120]}") from None

    def _one(self, sql: str, arguments: tuple[object, ...] = ()) -> tuple[Any, ...] | None:
        return next(self._rows(sql, arguments), None)

    def _text(self, blob: bytes | None) -> str:
        if blob is None:  # the query's bound on the stored size: the blob was never read
            raise FormatError(f"{self._name}: store damaged: an entry is stored in over {MAX_ENTRY} bytes")
        try:
            unpacker = zlib.decompressobj(zdict=self._dictionary)
            # bounded: a few hundred compressed bytes must not unpack into gigabytes
            text = unpacker.decompress(blob, MAX_ENTRY + 1)
            if len(text) > MAX_ENTRY or unpacker.unconsumed_tail:
                raise FormatError(f"{self._name}: store damaged: an entry unpacks to over {MAX_ENTRY} bytes")
            return (text + unpacker.flush()).decode("utf-8")
        except (zlib.error, UnicodeDecodeError, TypeError) as error:
            raise FormatError(f"{self._name}: store damaged: an entry does not decompress ({error})") from None

    def __getitem__(self, code: str) -> str:
        if not isinstance(code, str):  # the caller's mistake, not the file's
            raise KeyError(code)
        row = self._one(f"SELECT {_BOUNDED_ENTRY} FROM entries WHERE code = ?", (code,))
        if row is None:
            raise KeyError(code)
        return self._text(row[0])

    def __contains__(self, code: object) -> bool:
        return isinstance(code, str) and self._one("SELECT 1 FROM entries WHERE code = ?", (code,)) is not None

    def __iter__(self) -> Iterator[str]:
        return (code for (code,) in self._rows("SELECT code FROM entries ORDER BY code"))

    def __len__(self) -> int:
        return self._count

    def texts(self) -> Iterator[tuple[str, str]]:
        """Every (code, entry text), in code order, streamed (:func:`open_store` counted them)."""
        for code, blob in self._rows(f"SELECT code, {_BOUNDED_ENTRY} FROM entries ORDER BY code"):
            yield code, self._text(blob)
