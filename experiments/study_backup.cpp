#include "experiments/study_backup.h"

#include "common/error.h"
#include "common/files.h"
#include "experiments/sqlite_database.h"

#include <sqlite3.h>

namespace skinlab::experiments {
namespace fs = std::filesystem;

BackupSummary backupStudy(const fs::path& study, const fs::path& output, bool overwrite) {
    std::error_code ec;
    if (!fs::is_regular_file(study, ec)) throw InputError(study.string() + ": no such study file");
    if (fs::exists(output, ec)) {
        if (fs::equivalent(study, output, ec)) throw InputError(output.string() + ": is the study file itself");
        if (!overwrite) throw InputError(output.string() + ": already exists; choose another name or pass --overwrite");
    }
    // Read only: a study on a read-only mount is backed up too (common/sqlite_read.h).
    const std::unique_ptr<SqliteDatabase> opened = SqliteDatabase::openReadOnly(study.string());
    SqliteDatabase& source = *opened;
    {
        SqliteStatement s = source.prepare("SELECT value FROM meta WHERE key = 'format'");
        if (!s.step() || s.text(0) != "skinlab-study") throw InputError(study.string() + ": not a skinlab study file");
    }
    AtomicOutput out(output);
    fs::remove(out.tempPath(), ec);
    {
        SqliteDatabase copy(out.tempPath().string(), true);
        sqlite3_backup* backup = sqlite3_backup_init(copy.handle(), "main", source.handle(), "main");
        if (!backup) copy.fail("backup of " + study.string());
        // All pages in one step: one read transaction on the source, so one snapshot. Writers on other connections
        // go on (WAL); a lock held for longer than the busy timeout makes the step fail, and nothing is renamed.
        int rc = SQLITE_OK;
        do {
            rc = sqlite3_backup_step(backup, -1);
            if (rc == SQLITE_BUSY || rc == SQLITE_LOCKED) sqlite3_sleep(50);
        } while (rc == SQLITE_OK || rc == SQLITE_BUSY || rc == SQLITE_LOCKED);
        sqlite3_backup_finish(backup);
        if (rc != SQLITE_DONE)
            throw RuntimeError(study.string() + ": backup failed: " + sqlite3_errstr(rc) + " (nothing written to " +
                               output.string() + ")");
        // One self-contained file (no -wal beside it) that any SQLite opens as it is.
        copy.execute("PRAGMA journal_mode=DELETE");
        SqliteStatement check = copy.prepare("PRAGMA integrity_check");
        if (!check.step() || check.text(0) != "ok")
            throw RuntimeError(output.string() + ": the copy fails PRAGMA integrity_check; nothing written");
    }
    BackupSummary summary;
    {
        SqliteDatabase copy(out.tempPath().string(), false);
        SqliteStatement s =
            copy.prepare("SELECT (SELECT COUNT(*) FROM participants), (SELECT COUNT(*) FROM responses)");
        s.step();
        summary.participants = s.integer(0);
        summary.responses = s.integer(1);
    }
    out.commit();
    summary.bytes = fs::file_size(output, ec);
    return summary;
}

} // namespace skinlab::experiments
