#pragma once
// A thin RAII layer over the SQLite C API: a connection and prepared statements. Every SQLite failure becomes a
// RuntimeError carrying the database file and sqlite3_errmsg.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

struct sqlite3;
struct sqlite3_stmt;

namespace skinlab::experiments {

class SqliteStatement;

class SqliteDatabase {
public:
    // Opens (creating when `create`) the database file; a file it creates has mode 0600.
    SqliteDatabase(const std::string& path, bool create);
    // Opens an existing database for reading only, also on a read-only mount or in a folder this process may not
    // write (common/sqlite_read.h); InputError naming the file when it cannot be read.
    static std::unique_ptr<SqliteDatabase> openReadOnly(const std::string& path);
    ~SqliteDatabase();
    SqliteDatabase(const SqliteDatabase&) = delete;
    SqliteDatabase& operator=(const SqliteDatabase&) = delete;

    void execute(std::string_view sql);
    SqliteStatement prepare(std::string_view sql);
    std::int64_t lastInsertId() const;
    const std::string& path() const { return path_; }
    [[noreturn]] void fail(std::string_view what) const;
    sqlite3* handle() const { return db_; }
    // Whether SQLite can write through this connection (a file opened read-write may still be read-only to it).
    bool writable() const;

private:
    SqliteDatabase(std::string path, sqlite3* handle) : db_(handle), path_(std::move(path)) {}
    sqlite3* db_ = nullptr;
    std::string path_;
};

// Rolls back unless commit() was called.
class SqliteTransaction {
public:
    explicit SqliteTransaction(SqliteDatabase& db, bool immediate = true);
    ~SqliteTransaction();
    void commit();

private:
    SqliteDatabase& db_;
    bool done_ = false;
};

class SqliteStatement {
public:
    SqliteStatement(SqliteDatabase& db, sqlite3_stmt* statement) : db_(&db), statement_(statement) {}
    ~SqliteStatement();
    SqliteStatement(SqliteStatement&& other) noexcept;
    SqliteStatement& operator=(SqliteStatement&&) = delete;
    SqliteStatement(const SqliteStatement&) = delete;

    // Binding by 1-based parameter index.
    SqliteStatement& bind(int index, std::int64_t value);
    SqliteStatement& bind(int index, int value) { return bind(index, static_cast<std::int64_t>(value)); }
    SqliteStatement& bind(int index, double value);
    SqliteStatement& bind(int index, std::string_view value);
    SqliteStatement& bind(int index, const char* value) { return bind(index, std::string_view(value)); }
    SqliteStatement& bind(int index, const std::string& value) { return bind(index, std::string_view(value)); }
    SqliteStatement& bindNull(int index);

    // Advances; true while a row is available.
    bool step();
    // Runs a statement that returns no rows.
    void run();
    void reset();

    int columnCount() const;
    bool isNull(int column) const;
    std::int64_t integer(int column) const;
    double real(int column) const;
    std::string text(int column) const;
    std::optional<std::int64_t> optionalInteger(int column) const;

private:
    SqliteDatabase* db_;
    sqlite3_stmt* statement_;
};

} // namespace skinlab::experiments
