#pragma once
// The study file's schema: the tables and the responses_long view, writing a new file, and opening one (format
// check, connection settings, the tables added after format version 1 first shipped). Tables: docs/experiments.md
// ("The study file").
#include "experiments/stimulus_manifest.h"
#include "experiments/study_definition.h"
#include "experiments/study_records.h"

#include <filesystem>
#include <memory>
#include <string>

namespace skinlab::experiments {

class SqliteDatabase;

// Writes a new study file atomically (built under a temporary name, then renamed). Refuses to overwrite an
// existing file: a study holds responses that must never be lost by a repeated `create`.
void createStudyFile(const std::filesystem::path& path, const StudyDefinition& definition,
                     const std::string& designText, const StimulusManifest& manifest);

struct OpenedStudyFile {
    std::unique_ptr<SqliteDatabase> db;
    StudyDefinition definition;
};

// Opens a study file and checks its format and version (InputError otherwise), then reads its definition.
// readWrite: WAL journal, synchronous=FULL (COMMIT fsyncs the WAL), foreign keys, the schema brought up to date; a
// file or folder this process cannot write is refused (InputError) before anything else.
// readOnly: nothing is written (SqliteDatabase::openReadOnly); a file written by an older skinlab that lacks tables
// is brought up to date only where it can be written (else InputError saying so).
OpenedStudyFile openStudyFile(const std::filesystem::path& path, StudyAccess access = StudyAccess::readWrite);

// The value of `key` in table meta ("" for a missing "format"; RuntimeError for any other missing key).
std::string studyMeta(SqliteDatabase& db, const std::filesystem::path& path, const std::string& key);

} // namespace skinlab::experiments
