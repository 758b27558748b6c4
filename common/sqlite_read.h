#pragma once
// Reading an SQLite database (a study file) without writing anything, also where SQLite cannot write beside it: a
// read-only mount, or a folder the user may not write. Reference: docs/experiments.md ("Read-only study files").
//
// A database in WAL mode is read through its WAL index (<file>-shm), which SQLite creates beside the file when it is
// missing; it reads an existing one even from a read-only folder. Where the index is missing and cannot be created:
//  - without a write-ahead log holding transactions (no <file>-wal, or an empty one) every committed transaction is
//    in the file itself, so it is opened as an unchanging file (SQLite's `immutable=1`: no locks, no index). That is
//    correct as long as nothing writes the file meanwhile — a writer would have created the -wal, which no process
//    can do in that folder; one writing it through another, writable mount of the same folder is not seen;
//  - with a non-empty <file>-wal (a server stopped by kill -9, or one writing through another mount) the committed
//    transactions in it cannot be read without writing the index: InputError saying so (copy the folder somewhere
//    writable and read the copy).
#include <filesystem>

struct sqlite3;

namespace skinlab {

struct SqliteReader {
    sqlite3* handle = nullptr; // the caller's to close (sqlite3_close)
    bool immutable = false;    // opened as an unchanging file (see above)
};

// Opens `path` read-only and reads its schema once (so a file that is not a database fails here). InputError naming
// the file when it cannot be read.
SqliteReader openSqliteReadOnly(const std::filesystem::path& path);

// Whether `path` looks like an SQLite database from its first read (not empty, readable, and SQLite either reads its
// schema or finds a WAL-mode database whose index it cannot open). Never closes another connection's descriptor of
// the file in this process (SQLite keeps its locks: no plain descriptor is opened).
bool looksLikeSqliteDatabase(const std::filesystem::path& path);

} // namespace skinlab
