#pragma once
// `skinlab study backup STUDY.db OUT.db`: a consistent copy of a study file while it is being served, with
// SQLite's online backup API (sqlite3_backup_*, https://www.sqlite.org/backup.html). The copy is one snapshot
// (one read transaction on the source: every response committed before it began, none after), written under a
// temporary name in OUT's folder, switched to a self-contained rollback-journal file, checked
// (PRAGMA integrity_check), fsynced and renamed into place. The server keeps committing meanwhile (WAL).
#include <cstdint>
#include <filesystem>

namespace skinlab::experiments {

struct BackupSummary {
    std::int64_t participants = 0;
    std::int64_t responses = 0;
    std::uintmax_t bytes = 0;
};

// Throws InputError when `study` is not a study file, when `output` is the study itself, or when `output` exists
// and `overwrite` is false (an older backup is never replaced unless asked).
BackupSummary backupStudy(const std::filesystem::path& study, const std::filesystem::path& output, bool overwrite);

} // namespace skinlab::experiments
