#include "common/sqlite_read.h"

#include "common/error.h"

#include <cctype>
#include <sqlite3.h>
#include <string>
#include <unistd.h>

namespace skinlab {
namespace fs = std::filesystem;

namespace {

// A `file:` URI of `path` (absolute; every byte outside the unreserved set percent-encoded).
std::string fileUri(const fs::path& path, const char* query) {
    static const char* hex = "0123456789ABCDEF";
    std::string uri = "file:";
    for (const unsigned char c : fs::absolute(path).string()) {
        if (std::isalnum(c) || c == '/' || c == '-' || c == '.' || c == '_' || c == '~') {
            uri += static_cast<char>(c);
        } else {
            uri += '%';
            uri += hex[c >> 4];
            uri += hex[c & 15];
        }
    }
    return uri + "?" + query;
}

// Opens and reads the schema; the SQLite result code of the read (SQLITE_OK: `db` is usable).
int openAndProbe(const std::string& name, int flags, sqlite3*& db) {
    db = nullptr;
    int rc = sqlite3_open_v2(name.c_str(), &db, flags, nullptr);
    if (rc == SQLITE_OK) {
        sqlite3_busy_timeout(db, 10000); // a writer's lock (another process) is waited for
        rc = sqlite3_exec(db, "SELECT count(*) FROM sqlite_master", nullptr, nullptr, nullptr);
    }
    return rc;
}

std::string closeWithMessage(sqlite3* db) {
    std::string message = db ? sqlite3_errmsg(db) : "out of memory";
    sqlite3_close(db);
    return message;
}

bool folderWritable(const fs::path& path) {
    const fs::path folder = fs::absolute(path).parent_path();
    return ::access(folder.c_str(), W_OK) == 0;
}

} // namespace

SqliteReader openSqliteReadOnly(const fs::path& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw InputError(path.string() + ": no such file");
    sqlite3* db = nullptr;
    const int rc = openAndProbe(path.string(), SQLITE_OPEN_READONLY | SQLITE_OPEN_FULLMUTEX, db);
    if (rc == SQLITE_OK) return {db, false};
    const std::string message = closeWithMessage(db);
    if ((rc & 0xff) != SQLITE_CANTOPEN || folderWritable(path))
        throw InputError(path.string() + ": cannot read the database: " + message);
    // A WAL-mode database whose index cannot be created in a read-only folder.
    const fs::path wal = path.string() + "-wal";
    if (fs::exists(wal, ec) && fs::file_size(wal, ec) > 0)
        throw InputError(path.string() + ": cannot read it here: its folder is read-only and holds " + wal.string() +
                         " (committed transactions not yet in the file) without the index SQLite needs to read "
                         "them (" +
                         path.filename().string() + "-shm); copy the folder somewhere writable and read the copy");
    if (openAndProbe(fileUri(path, "immutable=1"), SQLITE_OPEN_READONLY | SQLITE_OPEN_URI | SQLITE_OPEN_FULLMUTEX,
                     db) != SQLITE_OK)
        throw InputError(path.string() + ": cannot read the database: " + closeWithMessage(db));
    return {db, true};
}

bool looksLikeSqliteDatabase(const fs::path& path) {
    std::error_code ec;
    const auto size = fs::file_size(path, ec);
    if (ec || size == 0 || ::access(path.c_str(), R_OK) != 0) return false;
    sqlite3* db = nullptr;
    const int rc = openAndProbe(path.string(), SQLITE_OPEN_READONLY, db);
    sqlite3_close(db);
    // SQLITE_CANTOPEN after the file was read: a database in WAL mode whose index cannot be opened here.
    return rc == SQLITE_OK || (rc & 0xff) == SQLITE_CANTOPEN;
}

} // namespace skinlab
