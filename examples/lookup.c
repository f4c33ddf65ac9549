/* One configuration's entry from a cospherical pattern-table store (SQLite), in C.
 *
 *   cc lookup.c -lsqlite3 -lz -o lookup && ./lookup TABLE.sqlite CODE
 *
 * Prints the entry's JSON text (the same text as the YAML table's line for CODE).
 * Each entry is compressed on its own with zlib and the store's preset dictionary. */
#include <sqlite3.h>
#include <stdio.h>
#include <zlib.h>

static int fail(const char *what) {
    fprintf(stderr, "lookup: %s\n", what);
    return 2;
}

int main(int argc, char **argv) {
    static unsigned char text[1 << 20]; /* an entry is at most 1 MiB */
    sqlite3 *db;
    sqlite3_stmt *dictionary, *entry;
    z_stream z = {0};
    int status;

    if (argc != 3) return fail("usage: lookup TABLE.sqlite CODE");
    if (sqlite3_open_v2(argv[1], &db, SQLITE_OPEN_READONLY, NULL) != SQLITE_OK) return fail(sqlite3_errmsg(db));
    if (sqlite3_prepare_v2(db, "SELECT data FROM dictionary", -1, &dictionary, NULL) != SQLITE_OK
        || sqlite3_prepare_v2(db, "SELECT entry FROM entries WHERE code = ?", -1, &entry, NULL) != SQLITE_OK)
        return fail("not a pattern-table store");
    sqlite3_bind_text(entry, 1, argv[2], -1, SQLITE_STATIC);
    if (sqlite3_step(dictionary) != SQLITE_ROW) return fail("no dictionary: not a pattern-table store");
    if (sqlite3_step(entry) != SQLITE_ROW) return fail("no such configuration in the table");

    inflateInit(&z);
    z.next_in = (unsigned char *)sqlite3_column_blob(entry, 0);
    z.avail_in = (uInt)sqlite3_column_bytes(entry, 0);
    z.next_out = text;
    z.avail_out = sizeof text;
    status = inflate(&z, Z_FINISH);
    if (status == Z_NEED_DICT) { /* always, as written: the dictionary is the table's own */
        inflateSetDictionary(&z, sqlite3_column_blob(dictionary, 0), (uInt)sqlite3_column_bytes(dictionary, 0));
        status = inflate(&z, Z_FINISH);
    }
    if (status != Z_STREAM_END) return fail("the entry does not decompress: a damaged store");
    fwrite(text, 1, z.total_out, stdout);
    putchar('\n');

    inflateEnd(&z);
    sqlite3_finalize(dictionary);
    sqlite3_finalize(entry);
    sqlite3_close(db);
    return 0;
}
