#include "experiments/study_schema.h"

#include "common/error.h"
#include "common/hash.h"
#include "common/time.h"
#include "common/version.h"
#include "experiments/sqlite_database.h"
#include "experiments/study_rows.h"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <unistd.h>

namespace skinlab::experiments {
namespace fs = std::filesystem;

namespace {

constexpr const char* kFormat = "skinlab-study";
constexpr int kFormatVersion = 1;

// The schema. responses.trial_id is the PRIMARY KEY: at most one response per planned trial, whatever the
// network does. responses_long is contract 3 (read by analysis/scaling).
constexpr const char* kSchema = R"SQL(
CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE stimuli (
  id INTEGER PRIMARY KEY,            -- index in the study definition; URL /stimuli/<id>.png
  stimulus TEXT NOT NULL UNIQUE,     -- manifest id
  block TEXT NOT NULL,
  condition TEXT NOT NULL,
  png_path TEXT NOT NULL,            -- relative to the stimulus folder
  sha256 TEXT NOT NULL,
  width INTEGER NOT NULL,
  height INTEGER NOT NULL,
  is_reference INTEGER NOT NULL);
CREATE TABLE participants (
  id INTEGER PRIMARY KEY,
  participant_index INTEGER NOT NULL UNIQUE,
  label TEXT NOT NULL UNIQUE,
  token TEXT NOT NULL UNIQUE,
  join_key TEXT UNIQUE,              -- client-chosen key making a retried join return the same participant
  seed INTEGER NOT NULL,
  completion_code TEXT NOT NULL,
  created_at TEXT NOT NULL);
CREATE TABLE sessions (
  id INTEGER PRIMARY KEY,
  participant_id INTEGER NOT NULL REFERENCES participants(id),
  started_at TEXT NOT NULL,
  user_agent TEXT NOT NULL,
  viewport_width INTEGER NOT NULL,
  viewport_height INTEGER NOT NULL,
  device_pixel_ratio REAL NOT NULL);
CREATE TABLE trials (
  id INTEGER PRIMARY KEY,
  participant_id INTEGER NOT NULL REFERENCES participants(id),
  position INTEGER NOT NULL,
  kind TEXT NOT NULL CHECK (kind IN ('practice','test','repeat','catch')),
  block TEXT NOT NULL,
  condition_a TEXT NOT NULL,
  condition_b TEXT NOT NULL,
  stimulus_a INTEGER NOT NULL REFERENCES stimuli(id),
  stimulus_b INTEGER REFERENCES stimuli(id),      -- NULL: the blank panel of a blank catch trial
  a_on_left INTEGER NOT NULL,
  reference_stimulus INTEGER REFERENCES stimuli(id),
  expected TEXT CHECK (expected IN ('A','B')),
  UNIQUE (participant_id, position));
CREATE TABLE responses (
  trial_id INTEGER PRIMARY KEY REFERENCES trials(id),
  participant_id INTEGER NOT NULL REFERENCES participants(id),
  session_id INTEGER NOT NULL REFERENCES sessions(id),
  chosen TEXT NOT NULL CHECK (chosen IN ('A','B')),
  side TEXT NOT NULL CHECK (side IN ('left','right')),
  response_ms REAL NOT NULL,
  client_time TEXT NOT NULL,
  server_time TEXT NOT NULL,
  viewport_width INTEGER NOT NULL,
  viewport_height INTEGER NOT NULL,
  device_pixel_ratio REAL NOT NULL,
  user_agent TEXT NOT NULL);
CREATE INDEX responses_by_participant ON responses(participant_id);
)SQL";

// Added to format version 1 later (online studies): created when missing, so a study file written before them opens
// unchanged and gains them. trial_conditions.trial_id is a response's trial; viewing_conditions holds what the
// page reported when a session started (no row: a client that reported nothing beyond the viewport).
constexpr const char* kOnlineSchema = R"SQL(
CREATE TABLE IF NOT EXISTS recruitment (
  participant_id INTEGER PRIMARY KEY REFERENCES participants(id),
  platform TEXT NOT NULL,            -- prolific | mturk | sona | generic
  external_id TEXT NOT NULL,         -- PROLIFIC_PID, workerId, or the design's id_parameter
  external_study_id TEXT NOT NULL,   -- STUDY_ID, hitId ('' when not sent)
  external_session_id TEXT NOT NULL, -- SESSION_ID, assignmentId ('' when not sent)
  UNIQUE (platform, external_id));
CREATE TABLE IF NOT EXISTS viewing_conditions (
  session_id INTEGER PRIMARY KEY REFERENCES sessions(id),
  screen_width INTEGER NOT NULL,     -- CSS pixels
  screen_height INTEGER NOT NULL,
  screen_width_px INTEGER NOT NULL,  -- device pixels
  screen_height_px INTEGER NOT NULL,
  colour_depth INTEGER NOT NULL,
  fullscreen INTEGER NOT NULL,
  pointer_fine INTEGER NOT NULL,
  touch_points INTEGER NOT NULL,
  mobile INTEGER NOT NULL,
  pixels_per_mm REAL,                -- device pixels per mm (card calibration); NULL = not calibrated
  viewing_distance_mm REAL,
  pixels_per_degree REAL);
CREATE TABLE IF NOT EXISTS trial_conditions (
  trial_id INTEGER PRIMARY KEY REFERENCES responses(trial_id),
  page_hidden INTEGER NOT NULL,      -- the page was hidden (other tab, minimised) while the trial was shown
  focus_lost INTEGER NOT NULL,       -- the window lost the focus while the trial was shown
  fullscreen INTEGER NOT NULL);      -- full screen when answered
)SQL";

// Contract 3 (read by analysis/scaling), and `flagged` (1 = page hidden or focus lost while shown; NULL = not
// recorded) after it.
const std::string kResponsesView = std::string(R"SQL(
DROP VIEW IF EXISTS responses_long;
CREATE VIEW responses_long AS
  SELECT p.label AS observer, t.block AS scene, t.condition_a AS condition_A, t.condition_b AS condition_B,
         CASE r.chosen WHEN 'A' THEN 1 ELSE 0 END AS is_A_selected, t.a_on_left AS A_on_left,
         t.kind AS trial_kind,
         )SQL") + kCorrectSql + R"SQL( AS correct,
         r.response_ms AS response_ms,
         )SQL" + kFlaggedSql + R"SQL( AS flagged
  FROM responses r JOIN trials t ON t.id = r.trial_id JOIN participants p ON p.id = t.participant_id
  LEFT JOIN trial_conditions c ON c.trial_id = r.trial_id
  ORDER BY p.id, t.position;
)SQL";

// Added after format version 1 first shipped: the address each participant joined from, and every later visit of a
// participant: a join that resumed it (with its secret) or was refused (a platform id without it), each bounded by
// kMaxVisitsPerParticipant; and every session (page load), bounded by the sessions' limit.
constexpr const char* kVisitsSchema = R"SQL(
CREATE TABLE IF NOT EXISTS participant_addresses (
  participant_id INTEGER PRIMARY KEY REFERENCES participants(id),
  client_address TEXT NOT NULL,
  source TEXT NOT NULL CHECK (source IN ('peer','forwarded')),
  recorded_at TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS participant_visits (
  id INTEGER PRIMARY KEY,
  participant_id INTEGER NOT NULL REFERENCES participants(id),
  outcome TEXT NOT NULL CHECK (outcome IN ('resumed','refused','session')),
  client_address TEXT NOT NULL,
  source TEXT NOT NULL CHECK (source IN ('peer','forwarded')),
  recorded_at TEXT NOT NULL);
)SQL";

// Whether the file holds every table and view this version reads and writes.
bool schemaCurrent(SqliteDatabase& db) {
    SqliteStatement s = db.prepare(
        "SELECT (SELECT COUNT(*) FROM sqlite_master WHERE name IN ('trial_conditions', 'participant_addresses',"
        " 'participant_visits')), (SELECT COUNT(*) FROM pragma_table_info('responses_long') WHERE name = 'flagged')");
    s.step();
    return s.integer(0) == 3 && s.integer(1) == 1;
}

// Brings a study file's schema up to date (idempotent; writes only when something is missing).
void upgradeSchema(SqliteDatabase& db) {
    if (schemaCurrent(db)) return;
    SqliteTransaction tx(db);
    db.execute(kOnlineSchema);
    db.execute(kResponsesView);
    db.execute(kVisitsSchema);
    tx.commit();
}

bool writable(const fs::path& path) { return ::access(path.c_str(), W_OK) == 0; }

// The server writes every join and answer: a file or folder it cannot write is refused before it starts (not with
// a 500 for every participant). The folder holds SQLite's -wal and -shm files.
void requireWritable(const fs::path& path) {
    const fs::path folder = fs::absolute(path).parent_path();
    if (!writable(path))
        throw InputError(path.string() + ": the study file is not writable here (" + std::strerror(errno) +
                         "); the server stores every join and answer in it: fix its permissions, or serve a "
                         "writable copy");
    if (!writable(folder))
        throw InputError(path.string() + ": its folder " + folder.string() + " is not writable here (" +
                         std::strerror(errno) +
                         "); SQLite keeps the study's write-ahead log beside the file: serve "
                         "it from a writable folder");
}

void configureConnection(SqliteDatabase& db) {
    // WAL: readers (status, export) never block the writer; synchronous=FULL: COMMIT fsyncs the WAL, so a
    // committed response survives a crash or power loss (SQLite docs, "PRAGMA synchronous").
    db.execute("PRAGMA journal_mode=WAL");
    db.execute("PRAGMA synchronous=FULL");
    db.execute("PRAGMA foreign_keys=ON");
}

} // namespace

void createStudyFile(const fs::path& path, const StudyDefinition& definition, const std::string& designText,
                     const StimulusManifest& manifest) {
    std::error_code ec;
    if (fs::exists(path, ec))
        throw InputError(path.string() + ": already exists; a study file is never overwritten (it may hold "
                                         "responses) — choose another -o or remove it first");
    const fs::path temp = path.parent_path() / ("." + path.filename().string() + ".tmp-" + std::to_string(::getpid()));
    fs::remove(temp, ec);
    {
        SqliteDatabase db(temp.string(), true);
        // Built with a rollback journal; switched to WAL at the end, so the single finished file is renamed.
        db.execute("PRAGMA foreign_keys=ON");
        SqliteTransaction tx(db);
        db.execute(kSchema);
        db.execute(kOnlineSchema);
        db.execute(kResponsesView);
        db.execute(kVisitsSchema);
        SqliteStatement meta = db.prepare("INSERT INTO meta (key, value) VALUES (?, ?)");
        auto putMeta = [&](const std::string& key, const std::string& value) {
            meta.bind(1, key).bind(2, value);
            meta.run();
        };
        putMeta("format", kFormat);
        putMeta("format_version", std::to_string(kFormatVersion));
        putMeta("skinlab_version", version());
        putMeta("created_at", utcTimestamp());
        putMeta("design_toml", designText);
        putMeta("design_sha256", sha256Hex(designText));
        putMeta("definition", definition.toJson().dump());
        putMeta("manifest_json", manifest.text);
        putMeta("manifest_sha256", manifest.sha256);
        putMeta("stimuli_dir", manifest.folder.string());
        putMeta("stimulus_set", manifest.set);
        SqliteStatement stimulus = db.prepare(
            "INSERT INTO stimuli (id, stimulus, block, condition, png_path, sha256, width, height, is_reference)"
            " VALUES (?,?,?,?,?,?,?,?,?)");
        for (const StudyStimulus& s : definition.stimuli) {
            stimulus.bind(1, s.index).bind(2, s.id).bind(3, s.block).bind(4, s.condition).bind(5, s.pngPath);
            stimulus.bind(6, s.sha256).bind(7, s.width).bind(8, s.height).bind(9, s.reference ? 1 : 0);
            stimulus.run();
        }
        tx.commit();
        db.execute("PRAGMA journal_mode=WAL");
    }
    // fsync the finished file, then rename it into place.
    int fd = ::open(temp.c_str(), O_RDONLY);
    if (fd >= 0) {
        ::fsync(fd);
        ::close(fd);
    }
    fs::rename(temp, path, ec);
    if (ec) {
        fs::remove(temp, ec);
        throw InputError(path.string() + ": cannot write the study file: " + ec.message());
    }
}

OpenedStudyFile openStudyFile(const fs::path& path, StudyAccess access) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw InputError(path.string() + ": no such study file");
    OpenedStudyFile file;
    if (access == StudyAccess::readWrite) {
        requireWritable(path);
        file.db = std::make_unique<SqliteDatabase>(path.string(), false);
        if (!file.db->writable())
            throw InputError(path.string() + ": SQLite opened the study file read-only; the server stores every "
                                             "join and answer in it: serve a writable copy");
        configureConnection(*file.db);
    } else {
        file.db = SqliteDatabase::openReadOnly(path.string());
    }
    SqliteDatabase& db = *file.db;
    if (studyMeta(db, path, "format") != kFormat) throw InputError(path.string() + ": not a skinlab study file");
    if (studyMeta(db, path, "format_version") != std::to_string(kFormatVersion))
        throw InputError(path.string() + ": study file version " + studyMeta(db, path, "format_version") +
                         " is not supported");
    if (access == StudyAccess::readWrite) {
        upgradeSchema(db);
    } else if (!schemaCurrent(db)) {
        // Written by an older skinlab: brought up to date where it can be written, as a served file would be.
        if (writable(path) && writable(fs::absolute(path).parent_path()))
            return openStudyFile(path, StudyAccess::readWrite);
        throw InputError(path.string() + ": written by an older skinlab (tables added since are missing) and "
                                         "read-only here; copy it to a writable folder and read the copy");
    }
    file.definition = StudyDefinition::fromJson(nlohmann::json::parse(studyMeta(db, path, "definition")));
    return file;
}

std::string studyMeta(SqliteDatabase& db, const fs::path& path, const std::string& key) {
    SqliteStatement s = db.prepare("SELECT value FROM meta WHERE key = ?");
    s.bind(1, key);
    if (!s.step()) {
        if (key == "format") return "";
        throw RuntimeError(path.string() + ": meta key \"" + key + "\" missing");
    }
    return s.text(0);
}

} // namespace skinlab::experiments
