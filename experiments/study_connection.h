#pragma once
// An open study file as the parts of the store share it: the one SQLite connection, the mutex that guards it, and
// the study's definition (read once when the file is opened, never changed).
//
// Locking (the same for every part): `mutex` is held around every use of `db` by the server's threads, one
// transaction at a time (SQLite serialises writers anyway). The group commit (experiments/response_queue.h) has its
// own queue mutex, never held while waiting for `mutex`; an active design's posterior fits
// (experiments/active_design_state.h) each have a per-block mutex, taken before `mutex`, never after it.
#include "experiments/sqlite_database.h"
#include "experiments/study_definition.h"

#include <filesystem>
#include <memory>
#include <mutex>

namespace skinlab::experiments {

struct StudyConnection {
    std::filesystem::path path;
    std::unique_ptr<SqliteDatabase> db;
    StudyDefinition definition;
    std::mutex mutex; // one connection shared by the server's threads; SQLite serialises writers anyway
};

} // namespace skinlab::experiments
