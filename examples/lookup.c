/* One configuration's entry from a cospherical pattern-table store (SQLite), in C or C++.
 *
 *   cc lookup.c -lsqlite3 -lz -o lookup && ./lookup TABLE.sqlite CODE
 *   g++ -x c++ lookup.c -lsqlite3 -lz -o lookup                  (the same file as C++)
 *
 * Prints the entry's JSON text (the same text as the YAML table's line for CODE).
 * Each entry is compressed on its own with zlib and the store's preset dictionary.
 *
 * A store is a file from anywhere, so this reader refuses what `cospherical check`
 * refuses before it reads a byte of an entry: a schema other than the three tables
 * as written (a view can run for ever, a trigger or another table is not a store),
 * a wrong layout or count, a dictionary or entry longer than ever written (their
 * sizes are read from the record headers, never the data), an entry that unpacks
 * to more than 1 MiB or to text that is not one line of UTF-8 JSON. */
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <zlib.h>

#define MAX_ENTRY (1 << 20)        /* an entry's text, and its packed size: at most 1 MiB */
#define MAX_DICTIONARY 32768       /* zlib's window: a longer dictionary is never written */
#define MAX_HEADER 65536           /* the meta table's values */
#define MAX_COUNT 281474976710656. /* 16^12 configuration codes */

/* The store's schema exactly as cospherical writes it (and as `check` requires it). */
static const char *const SCHEMA[][3] = {
    {"table", "meta", "CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL)"},
    {"index", "sqlite_autoindex_meta_1", NULL},
    {"table", "entries", "CREATE TABLE entries (code TEXT PRIMARY KEY, entry BLOB NOT NULL) WITHOUT ROWID"},
    {"table", "dictionary", "CREATE TABLE dictionary (data BLOB NOT NULL)"},
};
#define SCHEMA_ROWS (sizeof SCHEMA / sizeof SCHEMA[0])

static int fail(const char *what) {
    fprintf(stderr, "lookup: %s\n", what);
    return 2;
}

static int same(const unsigned char *text, const char *expected) {
    return text == NULL ? expected == NULL : expected != NULL && strcmp((const char *)text, expected) == 0;
}

/* A regular file (a FIFO would block the open) whose database header says SQLite, a rollback
 * journal (WAL would need files beside it), and a length at least what its page count says
 * (a truncated store is refused, not half read). */
static int complete(const char *path) {
    unsigned char head[100];
    long long pages, page_size;
    struct stat info;
    size_t got;
    FILE *file;
    if (stat(path, &info) != 0 || !S_ISREG(info.st_mode) || (file = fopen(path, "rb")) == NULL) return 0;
    got = fread(head, 1, sizeof head, file);
    fclose(file);
    if (got != sizeof head || memcmp(head, "SQLite format 3", 16) != 0 || head[18] != 1 || head[19] != 1) return 0;
    page_size = head[16] << 8 | head[17];
    if (page_size == 1) page_size = 65536;
    pages = (long long)head[28] << 24 | head[29] << 16 | head[30] << 8 | head[31];
    return pages > 0 && (long long)info.st_size >= page_size * pages;
}

/* One row of a query of one value, or -1 when the query fails, 0 when it gives no row. */
static int one_row(sqlite3 *db, const char *sql, sqlite3_stmt **statement) {
    if (sqlite3_prepare_v2(db, sql, -1, statement, NULL) != SQLITE_OK) return -1;
    switch (sqlite3_step(*statement)) {
    case SQLITE_ROW: return 1;
    case SQLITE_DONE: return 0;
    default: return -1;
    }
}

/* The schema is the store's, row for row, before any query reads a table. */
static const char *check_schema(sqlite3 *db) {
    sqlite3_stmt *rows;
    int seen[SCHEMA_ROWS] = {0}, status;
    size_t k, found = 0;
    if (sqlite3_prepare_v2(db, "SELECT type, name, sql FROM sqlite_master", -1, &rows, NULL) != SQLITE_OK)
        return "not an SQLite database";
    while ((status = sqlite3_step(rows)) == SQLITE_ROW) {
        for (k = 0; k < SCHEMA_ROWS; k++)
            if (!seen[k] && same(sqlite3_column_text(rows, 0), SCHEMA[k][0])
                && same(sqlite3_column_text(rows, 1), SCHEMA[k][1]) && same(sqlite3_column_text(rows, 2), SCHEMA[k][2]))
                break;
        if (k == SCHEMA_ROWS) break; /* a view, a trigger, another table or index, a changed table */
        seen[k] = 1;
        found++;
    }
    sqlite3_finalize(rows);
    return status == SQLITE_DONE && found == SCHEMA_ROWS
               ? NULL
               : "not a pattern-table store: its schema is not meta, entries and dictionary as written";
}

/* The meta rows, the dictionary's size and the stored sizes of every entry, all read from record
 * headers (length() of a blob), and the entries counted: what `check` refuses, refused here. */
static const char *check_store(sqlite3 *db) {
    sqlite3_stmt *statement = NULL;
    const char *problem = NULL;
    double count = -1;
    int status;
    status = one_row(db, "SELECT (SELECT value FROM meta WHERE key = 'layout' AND length(value) <= 16), "
                         "(SELECT count(*) FROM meta WHERE key = 'header' AND length(value) <= 65536), "
                         "(SELECT value FROM meta WHERE key = 'count' AND length(value) <= 16)", &statement);
    if (status != 1 || !same(sqlite3_column_text(statement, 0), "1") || sqlite3_column_int(statement, 1) != 1
        || sqlite3_column_type(statement, 2) != SQLITE_TEXT)
        problem = "not a pattern-table store of layout 1 with a header and a count";
    else {
        const char *text = (const char *)sqlite3_column_text(statement, 2);
        char *end;
        count = strtod(text, &end);
        if (*text < '0' || *text > '9' || *end != '\0' || count > MAX_COUNT) problem = "store damaged: its count";
    }
    sqlite3_finalize(statement);
    if (problem) return problem;
    status = one_row(db, "SELECT count(*), sum(typeof(data) = 'blob' AND length(data) <= 32768) FROM dictionary",
                     &statement);
    if (status != 1 || sqlite3_column_int(statement, 0) != 1 || sqlite3_column_int(statement, 1) != 1)
        problem = "store damaged: not one dictionary of at most 32768 bytes";
    sqlite3_finalize(statement);
    if (problem) return problem;
    /* dbstat gives each page's largest record from the cell headers (a code's length() would read a
     * text whole); an SQLite built without it falls back to the scan of lengths */
    status = one_row(db, "SELECT 1 FROM dbstat WHERE name = 'entries' AND mx_payload > 2 * 1048576 + 64 LIMIT 1",
                     &statement);
    sqlite3_finalize(statement);
    if (status == 1) return "store damaged: an entry is stored in over 1048576 bytes";
    status = one_row(db, "SELECT count(*), sum(typeof(entry) <> 'blob' OR length(entry) > 1048576 "
                         "OR length(code) > 1048576) FROM entries", &statement);
    if (status != 1) problem = "store damaged: its entries cannot be read";
    else if (sqlite3_column_int64(statement, 1) != 0)
        problem = "store damaged: an entry is not a blob, or is stored in over 1048576 bytes";
    else if ((double)sqlite3_column_int64(statement, 0) != count)
        problem = "store damaged: its entries are not as many as its count says";
    sqlite3_finalize(statement);
    return problem;
}

/* The entry's text is one line of UTF-8 (JSON escapes every control character in a string):
 * nothing printed can move a terminal's cursor or pass for another line. */
static int one_line_of_utf8(const unsigned char *text, size_t length) {
    size_t i = 0, more, k;
    while (i < length) {
        unsigned char c = text[i++];
        unsigned long point;
        if (c < 0x20 || c == 0x7f) return 0;
        if (c < 0x80) continue;
        if (c >= 0xc2 && c <= 0xdf) more = 1, point = c & 0x1f;
        else if (c >= 0xe0 && c <= 0xef) more = 2, point = c & 0x0f;
        else if (c >= 0xf0 && c <= 0xf4) more = 3, point = c & 0x07;
        else return 0;
        if (length - i < more) return 0;
        for (k = 0; k < more; k++, i++) {
            if ((text[i] & 0xc0) != 0x80) return 0;
            point = point << 6 | (text[i] & 0x3f);
        }
        if ((more == 2 && (point < 0x800 || (point >= 0xd800 && point <= 0xdfff)))
            || (more == 3 && (point < 0x10000 || point > 0x10ffff)) || (point >= 0x80 && point <= 0x9f))
            return 0; /* overlong, a surrogate, beyond Unicode, or a C1 control (NEL, CSI) */
    }
    return 1;
}

int main(int argc, char **argv) {
    static unsigned char text[MAX_ENTRY]; /* an entry is at most 1 MiB */
    sqlite3 *db = NULL;
    sqlite3_stmt *dictionary = NULL, *entry = NULL;
    z_stream z;
    const char *problem;
    int status;

    if (argc != 3) return fail("usage: lookup TABLE.sqlite CODE");
    if (!complete(argv[1])) return fail("not a complete pattern-table store (truncated, in WAL mode, or not SQLite)");
    if (sqlite3_open_v2(argv[1], &db, SQLITE_OPEN_READONLY, NULL) != SQLITE_OK) return fail(sqlite3_errmsg(db));
#ifdef SQLITE_DBCONFIG_TRUSTED_SCHEMA
    sqlite3_db_config(db, SQLITE_DBCONFIG_TRUSTED_SCHEMA, 0, (int *)NULL); /* no function runs from the schema */
#endif
    if ((problem = check_schema(db)) != NULL || (problem = check_store(db)) != NULL) return fail(problem);
    /* the stored sizes were checked above; checked again here, for a file changed since */
    if (one_row(db, "SELECT CASE WHEN length(data) <= 32768 THEN data END FROM dictionary", &dictionary) != 1
        || sqlite3_column_type(dictionary, 0) != SQLITE_BLOB)
        return fail("store damaged: its dictionary");
    if (sqlite3_prepare_v2(db, "SELECT CASE WHEN length(entry) <= 1048576 THEN entry END FROM entries WHERE code = ?",
                           -1, &entry, NULL) != SQLITE_OK)
        return fail("store damaged: its entries cannot be read");
    sqlite3_bind_text(entry, 1, argv[2], -1, SQLITE_STATIC);
    status = sqlite3_step(entry);
    if (status == SQLITE_DONE) return fail("no such configuration in the table");
    if (status != SQLITE_ROW || sqlite3_column_type(entry, 0) != SQLITE_BLOB) return fail("store damaged: the entry");

    memset(&z, 0, sizeof z);
    if (inflateInit(&z) != Z_OK) return fail("zlib cannot start");
    z.next_in = (Bytef *)sqlite3_column_blob(entry, 0);
    z.avail_in = (uInt)sqlite3_column_bytes(entry, 0);
    z.next_out = text;
    z.avail_out = sizeof text; /* bounded: a few hundred packed bytes must not unpack into gigabytes */
    status = inflate(&z, Z_FINISH);
    if (status == Z_NEED_DICT) { /* always, as written: the dictionary is the table's own */
        status = inflateSetDictionary(&z, (const Bytef *)sqlite3_column_blob(dictionary, 0),
                                      (uInt)sqlite3_column_bytes(dictionary, 0));
        if (status == Z_OK) status = inflate(&z, Z_FINISH);
    }
    if (status != Z_STREAM_END || z.avail_in != 0)
        return fail("store damaged: the entry does not decompress, or unpacks to over 1048576 bytes");
    if (!one_line_of_utf8(text, z.total_out)) return fail("store damaged: the entry is not one line of UTF-8");
    fwrite(text, 1, z.total_out, stdout);
    putchar('\n');

    inflateEnd(&z);
    sqlite3_finalize(dictionary);
    sqlite3_finalize(entry);
    sqlite3_close(db);
    return 0;
}
