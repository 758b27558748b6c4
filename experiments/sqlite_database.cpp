#include "experiments/sqlite_database.h"

#include "common/error.h"
#include "common/sqlite_read.h"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <sqlite3.h>
#include <unistd.h>

namespace skinlab::experiments {

SqliteDatabase::SqliteDatabase(const std::string& path, bool create) : path_(path) {
    if (create) {
        // A study holds personal data (platform ids, addresses) and participant secrets: a new file is readable by
        // its owner only, whatever the umask. SQLite gives its -wal, -shm and journal files the database's mode.
        const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
        if (fd < 0 && errno != EEXIST)
            throw InputError(path + ": cannot create the study database: " + std::strerror(errno));
        if (fd >= 0) ::close(fd);
    }
    const int flags = SQLITE_OPEN_READWRITE | (create ? SQLITE_OPEN_CREATE : 0) | SQLITE_OPEN_FULLMUTEX;
    if (sqlite3_open_v2(path.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
        std::string message = db_ ? sqlite3_errmsg(db_) : "out of memory";
        sqlite3_close(db_);
        db_ = nullptr;
        throw InputError(path + ": cannot open the study database: " + message);
    }
    // Wait for another process's write lock (e.g. `study export` while `study serve` commits) instead of failing.
    sqlite3_busy_timeout(db_, 10000);
}

std::unique_ptr<SqliteDatabase> SqliteDatabase::openReadOnly(const std::string& path) {
    return std::unique_ptr<SqliteDatabase>(new SqliteDatabase(path, openSqliteReadOnly(path).handle));
}

SqliteDatabase::~SqliteDatabase() { sqlite3_close(db_); }

bool SqliteDatabase::writable() const { return sqlite3_db_readonly(db_, "main") == 0; }

void SqliteDatabase::fail(std::string_view what) const {
    throw RuntimeError(path_ + ": SQLite: " + std::string(what) + ": " + sqlite3_errmsg(db_));
}

void SqliteDatabase::execute(std::string_view sql) {
    char* error = nullptr;
    if (sqlite3_exec(db_, std::string(sql).c_str(), nullptr, nullptr, &error) != SQLITE_OK) {
        std::string message = error ? error : sqlite3_errmsg(db_);
        sqlite3_free(error);
        throw RuntimeError(path_ + ": SQLite: " + message + " (in: " + std::string(sql.substr(0, 80)) + ")");
    }
}

SqliteStatement SqliteDatabase::prepare(std::string_view sql) {
    sqlite3_stmt* statement = nullptr;
    if (sqlite3_prepare_v2(db_, sql.data(), static_cast<int>(sql.size()), &statement, nullptr) != SQLITE_OK)
        fail("prepare \"" + std::string(sql.substr(0, 80)) + "\"");
    return SqliteStatement(*this, statement);
}

std::int64_t SqliteDatabase::lastInsertId() const { return sqlite3_last_insert_rowid(db_); }

SqliteTransaction::SqliteTransaction(SqliteDatabase& db, bool immediate) : db_(db) {
    // IMMEDIATE takes the write lock up front, so the checks made inside the transaction still hold at COMMIT.
    db_.execute(immediate ? "BEGIN IMMEDIATE" : "BEGIN");
}

SqliteTransaction::~SqliteTransaction() {
    if (!done_) sqlite3_exec(db_.handle(), "ROLLBACK", nullptr, nullptr, nullptr);
}

void SqliteTransaction::commit() {
    db_.execute("COMMIT");
    done_ = true;
}

SqliteStatement::~SqliteStatement() { sqlite3_finalize(statement_); }

SqliteStatement::SqliteStatement(SqliteStatement&& other) noexcept : db_(other.db_), statement_(other.statement_) {
    other.statement_ = nullptr;
}

SqliteStatement& SqliteStatement::bind(int index, std::int64_t value) {
    if (sqlite3_bind_int64(statement_, index, value) != SQLITE_OK) db_->fail("bind");
    return *this;
}
SqliteStatement& SqliteStatement::bind(int index, double value) {
    if (sqlite3_bind_double(statement_, index, value) != SQLITE_OK) db_->fail("bind");
    return *this;
}
SqliteStatement& SqliteStatement::bind(int index, std::string_view value) {
    if (sqlite3_bind_text(statement_, index, value.data(), static_cast<int>(value.size()), SQLITE_TRANSIENT) !=
        SQLITE_OK)
        db_->fail("bind");
    return *this;
}
SqliteStatement& SqliteStatement::bindNull(int index) {
    if (sqlite3_bind_null(statement_, index) != SQLITE_OK) db_->fail("bind");
    return *this;
}

bool SqliteStatement::step() {
    const int rc = sqlite3_step(statement_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    db_->fail("step");
}

void SqliteStatement::run() {
    while (step()) {
    }
    reset();
}

void SqliteStatement::reset() {
    sqlite3_reset(statement_);
    sqlite3_clear_bindings(statement_);
}

int SqliteStatement::columnCount() const { return sqlite3_column_count(statement_); }
bool SqliteStatement::isNull(int column) const { return sqlite3_column_type(statement_, column) == SQLITE_NULL; }
std::int64_t SqliteStatement::integer(int column) const { return sqlite3_column_int64(statement_, column); }
double SqliteStatement::real(int column) const { return sqlite3_column_double(statement_, column); }
std::string SqliteStatement::text(int column) const {
    const unsigned char* t = sqlite3_column_text(statement_, column);
    return t ? std::string(reinterpret_cast<const char*>(t),
                           static_cast<std::size_t>(sqlite3_column_bytes(statement_, column)))
             : std::string();
}
std::optional<std::int64_t> SqliteStatement::optionalInteger(int column) const {
    if (isNull(column)) return std::nullopt;
    return integer(column);
}

} // namespace skinlab::experiments
