#include "experiments/study_store.h"

#include "common/time.h"
#include "common/error.h"
#include "common/hash.h"
#include "common/version.h"
#include "experiments/active_plan.h"
#include "experiments/request_error.h"
#include "experiments/sqlite_database.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fcntl.h>
#include <random>
#include <unistd.h>

namespace skinlab::experiments {
namespace fs = std::filesystem;

namespace {

constexpr const char* kFormat = "skinlab-study";
constexpr int kFormatVersion = 1;
constexpr std::size_t kMaxStoredText = 512; // bytes of a stored client string (User-Agent, client time)

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
constexpr const char* kResponsesView = R"SQL(
DROP VIEW IF EXISTS responses_long;
CREATE VIEW responses_long AS
  SELECT p.label AS observer, t.block AS scene, t.condition_a AS condition_A, t.condition_b AS condition_B,
         CASE r.chosen WHEN 'A' THEN 1 ELSE 0 END AS is_A_selected, t.a_on_left AS A_on_left,
         t.kind AS trial_kind,
         CASE WHEN t.kind = 'catch' THEN (CASE WHEN r.chosen = t.expected THEN 1 ELSE 0 END) ELSE NULL END AS correct,
         r.response_ms AS response_ms,
         CASE WHEN c.trial_id IS NULL THEN NULL WHEN c.page_hidden OR c.focus_lost THEN 1 ELSE 0 END AS flagged
  FROM responses r JOIN trials t ON t.id = r.trial_id JOIN participants p ON p.id = t.participant_id
  LEFT JOIN trial_conditions c ON c.trial_id = r.trial_id
  ORDER BY p.id, t.position;
)SQL";

// Brings a study file's schema up to date (idempotent; writes only when something is missing).
void upgradeSchema(SqliteDatabase& db) {
    bool current = false;
    {
        SqliteStatement s =
            db.prepare("SELECT (SELECT COUNT(*) FROM sqlite_master WHERE name = 'trial_conditions'),"
                       " (SELECT COUNT(*) FROM pragma_table_info('responses_long') WHERE name = 'flagged')");
        s.step();
        current = s.integer(0) == 1 && s.integer(1) == 1;
    }
    if (current) return;
    SqliteTransaction tx(db);
    db.execute(kOnlineSchema);
    db.execute(kResponsesView);
    tx.commit();
}

void configureConnection(SqliteDatabase& db) {
    // WAL: readers (status, export) never block the writer; synchronous=FULL: COMMIT fsyncs the WAL, so a
    // committed response survives a crash or power loss (SQLite docs, "PRAGMA synchronous").
    db.execute("PRAGMA journal_mode=WAL");
    db.execute("PRAGMA synchronous=FULL");
    db.execute("PRAGMA foreign_keys=ON");
}

std::string makeCompletionCode() {
    // Unambiguous characters only (no 0/O, 1/I/L), 8 of them.
    static const char alphabet[] = "ABCDEFGHJKMNPQRSTUVWXYZ23456789";
    const std::string hex = randomHex(8);
    std::string code;
    for (std::size_t i = 0; i < 8; ++i) {
        const unsigned value = static_cast<unsigned>(std::stoul(hex.substr(i * 2, 2), nullptr, 16));
        code += alphabet[value % (sizeof(alphabet) - 1)];
    }
    return code;
}

void insertTrials(SqliteDatabase& db, std::int64_t participantId, const std::vector<PlannedTrial>& plan,
                  int firstPosition = 0) {
    SqliteStatement insert = db.prepare(
        "INSERT INTO trials (participant_id, position, kind, block, condition_a, condition_b, stimulus_a, stimulus_b,"
        " a_on_left, reference_stimulus, expected) VALUES (?,?,?,?,?,?,?,?,?,?,?)");
    int position = firstPosition;
    for (const PlannedTrial& t : plan) {
        insert.bind(1, participantId).bind(2, position++).bind(3, trialKindName(t.kind)).bind(4, t.block);
        insert.bind(5, t.conditionA).bind(6, t.conditionB).bind(7, t.stimulusA);
        if (t.stimulusB == kBlankStimulus) insert.bindNull(8);
        else insert.bind(8, t.stimulusB);
        insert.bind(9, t.aOnLeft ? 1 : 0);
        if (t.referenceStimulus < 0) insert.bindNull(10);
        else insert.bind(10, t.referenceStimulus);
        if (t.expected) insert.bind(11, std::string(1, t.expected));
        else insert.bindNull(11);
        insert.run();
    }
}

constexpr const char* kTrialColumns =
    "id, participant_id, position, kind, block, condition_a, condition_b, stimulus_a, stimulus_b, a_on_left,"
    " reference_stimulus, expected";

TrialRecord readTrial(const SqliteStatement& s) {
    TrialRecord t;
    t.id = s.integer(0);
    t.participantId = s.integer(1);
    t.position = static_cast<int>(s.integer(2));
    t.plan.kind = trialKindFromName(s.text(3));
    t.plan.block = s.text(4);
    t.plan.conditionA = s.text(5);
    t.plan.conditionB = s.text(6);
    t.plan.stimulusA = static_cast<int>(s.integer(7));
    t.plan.stimulusB = s.isNull(8) ? kBlankStimulus : static_cast<int>(s.integer(8));
    t.plan.aOnLeft = s.integer(9) != 0;
    t.plan.referenceStimulus = s.isNull(10) ? -1 : static_cast<int>(s.integer(10));
    const std::string expected = s.text(11);
    t.plan.expected = expected.empty() ? 0 : expected[0];
    return t;
}

ParticipantRecord readParticipant(const SqliteStatement& s) {
    ParticipantRecord p;
    p.id = s.integer(0);
    p.index = s.integer(1);
    p.label = s.text(2);
    p.token = s.text(3);
    p.seed = static_cast<std::uint64_t>(s.integer(4));
    p.completionCode = s.text(5);
    p.createdAt = s.text(6);
    return p;
}

constexpr const char* kParticipantColumns = "id, participant_index, label, token, seed, completion_code, created_at";

} // namespace

std::string randomHex(std::size_t bytes) {
    std::random_device device; // /dev/urandom on Linux (libstdc++)
    std::string out;
    static const char digits[] = "0123456789abcdef";
    for (std::size_t i = 0; i < bytes; ++i) {
        const unsigned value = device() & 0xFFu;
        out += digits[value >> 4];
        out += digits[value & 15u];
    }
    return out;
}

std::int64_t trialReference(const std::string& token, std::int64_t trialId) {
    // 20 bits of SHA-256(token, id) above the 32-bit row id: below 2^53, so JavaScript numbers carry it exactly.
    const std::string digest = sha256Hex(token + ":" + std::to_string(trialId));
    const std::int64_t tag = static_cast<std::int64_t>(std::stoul(digest.substr(0, 5), nullptr, 16)) | 1;
    return (tag << 32) | (trialId & 0xFFFFFFFFll);
}

std::string validUtf8(std::string_view text, std::size_t maxBytes) {
    // Well-formed UTF-8 (RFC 3629: no overlongs, no surrogates, at most U+10FFFF); every ill-formed byte becomes
    // U+FFFD, and the result is cut before `maxBytes` on a character boundary.
    static const std::string_view replacement = "\xEF\xBF\xBD";
    std::string out;
    std::size_t i = 0;
    auto append = [&](std::string_view piece) {
        if (out.size() + piece.size() > maxBytes) return false;
        out += piece;
        return true;
    };
    while (i < text.size()) {
        const auto b = static_cast<unsigned char>(text[i]);
        std::size_t length = 0;
        unsigned char low = 0x80, high = 0xBF;
        if (b < 0x80) length = 1;
        else if (b >= 0xC2 && b <= 0xDF) length = 2;
        else if (b >= 0xE0 && b <= 0xEF) {
            length = 3;
            if (b == 0xE0) low = 0xA0;
            if (b == 0xED) high = 0x9F;
        } else if (b >= 0xF0 && b <= 0xF4) {
            length = 4;
            if (b == 0xF0) low = 0x90;
            if (b == 0xF4) high = 0x8F;
        }
        bool ok = length > 0 && i + length <= text.size();
        for (std::size_t k = 1; ok && k < length; ++k) {
            const auto c = static_cast<unsigned char>(text[i + k]);
            const unsigned char lo = k == 1 ? low : 0x80, hi = k == 1 ? high : 0xBF;
            ok = c >= lo && c <= hi;
        }
        if (ok && b < 0x20 && b != '\t') ok = false; // control characters have no place in a stored header
        if (!append(ok ? text.substr(i, length) : replacement)) break;
        if (ok) i += length;
        else {
            // Skip the lead byte and any continuation bytes that belonged to it.
            ++i;
            while (i < text.size() && (static_cast<unsigned char>(text[i]) & 0xC0) == 0x80) ++i;
        }
    }
    return out;
}

void StudyStore::create(const fs::path& path, const StudyDefinition& definition, const std::string& designText,
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

StudyStore::StudyStore(const fs::path& path) : path_(path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw InputError(path.string() + ": no such study file");
    db_ = std::make_unique<SqliteDatabase>(path.string(), false);
    configureConnection(*db_);
    if (meta("format") != kFormat) throw InputError(path.string() + ": not a skinlab study file");
    if (meta("format_version") != std::to_string(kFormatVersion))
        throw InputError(path.string() + ": study file version " + meta("format_version") + " is not supported");
    upgradeSchema(*db_);
    definition_ = StudyDefinition::fromJson(nlohmann::json::parse(meta("definition")));
    // Added after format version 1 first shipped: created on open, so older study files gain it too.
    db_->execute("CREATE TABLE IF NOT EXISTS participant_addresses ("
                 " participant_id INTEGER PRIMARY KEY REFERENCES participants(id),"
                 " client_address TEXT NOT NULL,"
                 " source TEXT NOT NULL CHECK (source IN ('peer','forwarded')),"
                 " recorded_at TEXT NOT NULL)");
    // Every later visit of a participant: a join that resumed it (with its secret) or was refused (a platform id
    // without it), bounded by kMaxVisitsPerParticipant; and every session (page load), bounded by the sessions'
    // limit.
    db_->execute("CREATE TABLE IF NOT EXISTS participant_visits ("
                 " id INTEGER PRIMARY KEY,"
                 " participant_id INTEGER NOT NULL REFERENCES participants(id),"
                 " outcome TEXT NOT NULL CHECK (outcome IN ('resumed','refused','session')),"
                 " client_address TEXT NOT NULL,"
                 " source TEXT NOT NULL CHECK (source IN ('peer','forwarded')),"
                 " recorded_at TEXT NOT NULL)");
    for (std::size_t b = 0; b < definition_.blocks.size(); ++b)
        posteriorCache_.push_back(std::make_unique<BlockPosteriorCache>());
}

void StudyStore::recordJoinAddress(std::int64_t participantId, const std::string& address, const std::string& source) {
    std::lock_guard lock(mutex_);
    SqliteStatement s =
        db_->prepare("INSERT OR IGNORE INTO participant_addresses (participant_id, client_address, source,"
                     " recorded_at) VALUES (?,?,?,?)");
    s.bind(1, participantId).bind(2, validUtf8(address, 64)).bind(3, source).bind(4, utcTimestamp());
    s.run();
}

StudyStore::~StudyStore() = default;

std::string StudyStore::meta(const std::string& key) const {
    SqliteStatement s = db_->prepare("SELECT value FROM meta WHERE key = ?");
    s.bind(1, key);
    if (!s.step()) {
        if (key == "format") return "";
        throw RuntimeError(path_.string() + ": meta key \"" + key + "\" missing");
    }
    return s.text(0);
}

std::vector<std::string> StudyStore::simulatedLabels() const {
    // simulatedJoinKey(): "sim-" and 40 hexadecimal digits.
    SqliteStatement s = db_->prepare("SELECT label FROM participants WHERE join_key LIKE 'sim-%' AND "
                                     "length(join_key) = 44 ORDER BY participant_index");
    std::vector<std::string> labels;
    while (s.step()) labels.push_back(s.text(0));
    return labels;
}

ParticipantRecord StudyStore::join(const std::string& requestedLabel, const std::string& joinKey,
                                   const std::optional<ExternalIds>& external,
                                   const std::optional<ClientOrigin>& origin) {
    bool created = false;
    ParticipantRecord p = joinLocked(requestedLabel, joinKey, external, origin, created);
    // Active design: the first stretch (practice trials, the first batch) is planned outside the lock and stored
    // before the join is answered. Should the process die in between, the participant's first nextTrial() plans it.
    if (created && definition_.design.activePairs) extendActivePlan(p.id);
    return p;
}

void StudyStore::insertVisit(std::int64_t participantId, const char* outcome, const ClientOrigin& origin) {
    SqliteStatement s = db_->prepare("INSERT INTO participant_visits (participant_id, outcome, client_address, source,"
                                     " recorded_at) VALUES (?,?,?,?,?)");
    s.bind(1, participantId).bind(2, std::string(outcome)).bind(3, validUtf8(origin.address, 64));
    s.bind(4, origin.source).bind(5, utcTimestamp());
    s.run();
}

int StudyStore::visitCount(std::int64_t participantId) {
    SqliteStatement s = db_->prepare("SELECT COUNT(*) FROM participant_visits WHERE participant_id = ? AND outcome IN"
                                     " ('resumed', 'refused')");
    s.bind(1, participantId);
    s.step();
    return static_cast<int>(s.integer(0));
}

ParticipantRecord StudyStore::joinLocked(const std::string& requestedLabel, const std::string& joinKey,
                                         const std::optional<ExternalIds>& external,
                                         const std::optional<ClientOrigin>& origin, bool& created) {
    std::lock_guard lock(mutex_);
    SqliteTransaction tx(*db_);
    // A returning participant: recorded (address, time) with every resume; bounded per participant.
    auto resume = [&](ParticipantRecord existing) {
        if (origin) {
            if (visitCount(existing.id) >= kMaxVisitsPerParticipant)
                throw RequestError(429, "this participant has resumed too often; contact the researcher");
            insertVisit(existing.id, "resumed", *origin);
            tx.commit();
        }
        existing.resumed = true;
        return existing;
    };
    if (external) {
        // One platform id, one participant. A second visit resumes the first only with the first join's key (the
        // same browser) or the platform's per-attempt session id it joined with (the same platform link): anyone
        // may know or guess a platform id, only the participant holds these.
        SqliteStatement s = db_->prepare(std::string("SELECT ") + kParticipantColumns +
                                         ", join_key, rec.external_session_id FROM participants"
                                         " JOIN recruitment rec ON rec.participant_id = participants.id"
                                         " WHERE rec.platform = ? AND rec.external_id = ?");
        s.bind(1, external->platform).bind(2, external->id);
        if (s.step()) {
            ParticipantRecord existing = readParticipant(s);
            const std::string storedKey = s.isNull(7) ? "" : s.text(7), storedSession = s.text(8);
            s.reset();
            const bool sameBrowser = !joinKey.empty() && joinKey == storedKey;
            const bool sameAttempt = !external->session.empty() && external->session == storedSession;
            if (sameBrowser || sameAttempt) return resume(existing);
            if (origin && visitCount(existing.id) < kMaxVisitsPerParticipant) {
                insertVisit(existing.id, "refused", *origin);
                tx.commit();
            }
            const std::string parameter = platformParameters(definition_.design.recruitment).id;
            throw RequestError(409, parameter + ": this " + external->platform +
                                        " id has already started this study in another browser or from another "
                                        "link; continue where you started (same browser, same link), or contact "
                                        "the researcher");
        }
    }
    if (!joinKey.empty()) {
        SqliteStatement s =
            db_->prepare(std::string("SELECT ") + kParticipantColumns + " FROM participants WHERE join_key = ?");
        s.bind(1, joinKey);
        if (s.step()) {
            ParticipantRecord existing = readParticipant(s);
            s.reset();
            // A join key belongs to one participant: not to another label, nor to another platform id.
            if ((!requestedLabel.empty() && existing.label != requestedLabel) || external)
                throw RequestError(409, "join_key: already used by another participant");
            return resume(existing);
        }
    }
    ParticipantRecord p;
    {
        SqliteStatement count = db_->prepare("SELECT COALESCE(MAX(participant_index) + 1, 0) FROM participants");
        count.step();
        p.index = count.integer(0);
    }
    if (!requestedLabel.empty()) {
        SqliteStatement taken = db_->prepare("SELECT 1 FROM participants WHERE label = ?");
        taken.bind(1, requestedLabel);
        if (taken.step())
            throw RequestError(409, "participant label \"" + requestedLabel +
                                        "\" is already taken; open that participant's link to resume");
    }
    if (requestedLabel.empty()) {
        // The default label follows the joining order, skipping labels already taken (an explicit label may equal a
        // later default one: "P007" joined by hand must not lock out every bare join after P006).
        SqliteStatement taken = db_->prepare("SELECT 1 FROM participants WHERE label = ?");
        for (std::int64_t n = p.index + 1;; ++n) {
            char defaultLabel[32];
            std::snprintf(defaultLabel, sizeof defaultLabel, "P%03lld", static_cast<long long>(n));
            taken.reset();
            taken.bind(1, std::string(defaultLabel));
            if (!taken.step()) {
                p.label = defaultLabel;
                break;
            }
        }
    } else {
        p.label = requestedLabel;
    }
    p.token = randomHex(16);
    p.seed = participantSeed(definition_.design.seed, p.index);
    p.completionCode = makeCompletionCode();
    p.createdAt = utcTimestamp();
    SqliteStatement insert = db_->prepare(
        "INSERT INTO participants (participant_index, label, token, join_key, seed, completion_code, created_at)"
        " VALUES (?,?,?,?,?,?,?)");
    insert.bind(1, p.index).bind(2, p.label).bind(3, p.token);
    if (joinKey.empty()) insert.bindNull(4);
    else insert.bind(4, joinKey);
    insert.bind(5, static_cast<std::int64_t>(p.seed)).bind(6, p.completionCode).bind(7, p.createdAt);
    insert.run();
    p.id = db_->lastInsertId();
    if (external) {
        SqliteStatement ids = db_->prepare("INSERT INTO recruitment (participant_id, platform, external_id,"
                                           " external_study_id, external_session_id) VALUES (?,?,?,?,?)");
        ids.bind(1, p.id).bind(2, external->platform).bind(3, external->id).bind(4, external->study);
        ids.bind(5, external->session);
        ids.run();
    }
    if (origin) {
        SqliteStatement a = db_->prepare("INSERT OR IGNORE INTO participant_addresses (participant_id, client_address,"
                                         " source, recorded_at) VALUES (?,?,?,?)");
        a.bind(1, p.id).bind(2, validUtf8(origin->address, 64)).bind(3, origin->source).bind(4, p.createdAt);
        a.run();
    }
    if (!definition_.design.activePairs) insertTrials(*db_, p.id, planTrials(definition_, p.index, p.seed));
    tx.commit();
    created = true;
    return p;
}

ParticipantRecord StudyStore::participant(const std::string& token) {
    std::lock_guard lock(mutex_);
    SqliteStatement s =
        db_->prepare(std::string("SELECT ") + kParticipantColumns + " FROM participants WHERE token = ?");
    s.bind(1, token);
    if (!s.step()) throw RequestError(404, "unknown participant");
    return readParticipant(s);
}

std::int64_t StudyStore::startSession(std::int64_t participantId, const std::string& userAgent, int viewportWidth,
                                      int viewportHeight, double devicePixelRatio,
                                      const std::optional<ViewingConditions>& viewing, int maxSessions,
                                      const std::optional<ClientOrigin>& origin) {
    std::lock_guard lock(mutex_);
    SqliteTransaction tx(*db_);
    if (maxSessions > 0) {
        // Each page load starts a session: a handful per participant is normal, thousands are a flood.
        SqliteStatement count = db_->prepare("SELECT COUNT(*) FROM sessions WHERE participant_id = ?");
        count.bind(1, participantId);
        count.step();
        if (count.integer(0) >= maxSessions)
            throw RequestError(429, "too many sessions for this participant (at most " + std::to_string(maxSessions) +
                                        "); contact the researcher");
    }
    SqliteStatement s = db_->prepare("INSERT INTO sessions (participant_id, started_at, user_agent, viewport_width, "
                                     "viewport_height, device_pixel_ratio)"
                                     " VALUES (?,?,?,?,?,?)");
    s.bind(1, participantId)
        .bind(2, utcTimestamp())
        .bind(3, validUtf8(userAgent, kMaxStoredText))
        .bind(4, viewportWidth);
    s.bind(5, viewportHeight);
    s.bind(6, devicePixelRatio);
    s.run();
    const std::int64_t session = db_->lastInsertId();
    if (viewing) {
        const ViewingConditions& v = *viewing;
        SqliteStatement c = db_->prepare(
            "INSERT INTO viewing_conditions (session_id, screen_width, screen_height, screen_width_px, "
            "screen_height_px,"
            " colour_depth, fullscreen, pointer_fine, touch_points, mobile, pixels_per_mm, viewing_distance_mm,"
            " pixels_per_degree) VALUES (?,?,?,?,?,?,?,?,?,?,?,?,?)");
        c.bind(1, session).bind(2, v.screenWidth).bind(3, v.screenHeight).bind(4, v.screenWidthPx);
        c.bind(5, v.screenHeightPx).bind(6, v.colourDepth).bind(7, v.fullscreen ? 1 : 0).bind(8, v.pointerFine ? 1 : 0);
        c.bind(9, v.touchPoints).bind(10, v.mobile ? 1 : 0);
        if (v.pixelsPerMm) c.bind(11, *v.pixelsPerMm);
        else c.bindNull(11);
        if (v.viewingDistanceMm) c.bind(12, *v.viewingDistanceMm);
        else c.bindNull(12);
        if (v.pixelsPerDegree) c.bind(13, *v.pixelsPerDegree);
        else c.bindNull(13);
        c.run();
    }
    if (origin) insertVisit(participantId, "session", *origin);
    tx.commit();
    return session;
}

std::optional<TrialRecord> StudyStore::nextTrial(std::int64_t participantId) {
    for (;;) {
        {
            std::lock_guard lock(mutex_);
            std::optional<TrialRecord> next = firstUnanswered(participantId);
            if (next || !definition_.design.activePairs) return next;
        }
        // Active design: every stored trial answered, so the next batch is planned and stored now (before it is
        // shown). When another request of the same participant stored one meanwhile, look again.
        if (extendActivePlan(participantId) == ActiveExtension::complete) {
            // The plan is complete — possibly because a concurrent request stored its last batch after the look
            // above, so its trials may still be unanswered: look once more.
            std::lock_guard lock(mutex_);
            return firstUnanswered(participantId);
        }
    }
}

std::optional<TrialRecord> StudyStore::firstUnanswered(std::int64_t participantId) {
    auto first = [&]() -> std::optional<TrialRecord> {
        SqliteStatement s =
            db_->prepare(std::string("SELECT ") + kTrialColumns +
                         " FROM trials WHERE participant_id = ? AND id NOT IN"
                         " (SELECT trial_id FROM responses WHERE participant_id = ?) ORDER BY position LIMIT 1");
        s.bind(1, participantId).bind(2, participantId);
        if (!s.step()) return std::nullopt;
        return readTrial(s);
    };
    return first();
}

// ---- Active designs (experiments/active_plan.h) ----

void StudyStore::loadActiveCounts() {
    if (activeCountsLoaded_) return;
    activeAnswers_.assign(definition_.blocks.size(), {});
    for (std::size_t b = 0; b < definition_.blocks.size(); ++b) {
        const StudyBlock& block = definition_.blocks[b];
        std::map<std::string, int> index;
        for (std::size_t i = 0; i < block.conditions.size(); ++i) index[block.conditions[i]] = static_cast<int>(i);
        // Every stored answer to a test trial of the block, of every participant, counted per ordered pair.
        SqliteStatement s = db_->prepare(
            "SELECT t.condition_a, t.condition_b, SUM(r.chosen = 'A'), SUM(r.chosen = 'B') FROM responses r"
            " JOIN trials t ON t.id = r.trial_id WHERE t.block = ? AND t.kind IN ('test','repeat')"
            " GROUP BY t.condition_a, t.condition_b");
        s.bind(1, block.name);
        BlockAnswers& answers = activeAnswers_[b];
        while (s.step()) {
            const auto a = index.find(s.text(0)), c = index.find(s.text(1));
            if (a == index.end() || c == index.end() || a->second == c->second) continue;
            const double aWon = static_cast<double>(s.integer(2)), cWon = static_cast<double>(s.integer(3));
            auto& entry = answers.counts[{std::min(a->second, c->second), std::max(a->second, c->second)}];
            entry.first += a->second < c->second ? aWon : cWon;
            entry.second += a->second < c->second ? cWon : aWon;
            answers.generation += static_cast<std::uint64_t>(aWon + cWon);
        }
    }
    activeCountsLoaded_ = true;
}

active::ScorePosterior StudyStore::blockPosterior(std::size_t b, std::uint64_t generation) {
    BlockPosteriorCache& cache = *posteriorCache_[b];
    std::lock_guard fitting(cache.mutex);
    if (cache.valid && cache.generation >= generation) return cache.posterior;
    // The latest answers (at least `generation` of them; more when some arrived while this request waited).
    std::vector<active::PairCount> counts;
    std::uint64_t latest = 0;
    {
        std::lock_guard lock(mutex_);
        loadActiveCounts();
        const BlockAnswers& answers = activeAnswers_[b];
        latest = answers.generation;
        for (const auto& [pair, won] : answers.counts)
            counts.push_back({pair.first, pair.second, won.first, won.second});
    }
    cache.posterior = active::fitPosteriorFromCounts(static_cast<int>(definition_.blocks[b].conditions.size()), counts);
    cache.generation = latest;
    cache.valid = true;
    return cache.posterior;
}

StudyStore::ActiveExtension StudyStore::extendActivePlan(std::int64_t participantId) {
    std::int64_t index = 0;
    std::uint64_t seed = 0;
    std::vector<PlannedTrial> stored;
    std::vector<std::uint64_t> generations;
    {
        std::lock_guard lock(mutex_);
        SqliteStatement s = db_->prepare("SELECT participant_index, seed FROM participants WHERE id = ?");
        s.bind(1, participantId);
        if (!s.step()) return ActiveExtension::complete;
        index = s.integer(0);
        seed = static_cast<std::uint64_t>(s.integer(1));
        SqliteStatement t = db_->prepare(std::string("SELECT ") + kTrialColumns +
                                         " FROM trials WHERE participant_id = ? ORDER BY position");
        t.bind(1, participantId);
        while (t.step()) stored.push_back(readTrial(t).plan);
        loadActiveCounts();
        for (const BlockAnswers& answers : activeAnswers_) generations.push_back(answers.generation);
    }
    // Planned without the store's lock: other requests go on meanwhile.
    const std::vector<PlannedTrial> next = nextActiveTrials(
        definition_, index, seed, stored, [&](std::size_t b) { return blockPosterior(b, generations[b]); });
    if (next.empty()) return ActiveExtension::complete;
    std::lock_guard lock(mutex_);
    SqliteTransaction tx(*db_);
    {
        // Re-check: nothing stored for this participant since the read above (a concurrent request planned).
        SqliteStatement s = db_->prepare("SELECT COUNT(*) FROM trials WHERE participant_id = ?");
        s.bind(1, participantId);
        s.step();
        if (s.integer(0) != static_cast<std::int64_t>(stored.size())) return ActiveExtension::raced;
    }
    insertTrials(*db_, participantId, next, static_cast<int>(stored.size()));
    tx.commit();
    return ActiveExtension::stored;
}

int StudyStore::plannedTrialCount() const {
    const StudyDefinition& d = definition_;
    return d.design.practiceTrials + d.testTrialCount() + d.repeatTrialCount() + d.catchTrialCount();
}

std::vector<TrialRecord> StudyStore::trials(std::int64_t participantId) {
    std::lock_guard lock(mutex_);
    SqliteStatement s = db_->prepare(std::string("SELECT ") + kTrialColumns +
                                     " FROM trials WHERE participant_id = ? ORDER BY position");
    s.bind(1, participantId);
    std::vector<TrialRecord> out;
    while (s.step()) out.push_back(readTrial(s));
    return out;
}

Progress StudyStore::progress(std::int64_t participantId) {
    std::lock_guard lock(mutex_);
    SqliteStatement s = db_->prepare("SELECT (SELECT COUNT(*) FROM responses WHERE participant_id = ?1),"
                                     " (SELECT COUNT(*) FROM trials WHERE participant_id = ?1)");
    s.bind(1, participantId);
    s.step();
    // An active design stores its test trials batch by batch; its length is known from the design.
    const int total = definition_.design.activePairs ? plannedTrialCount() : static_cast<int>(s.integer(1));
    return {static_cast<int>(s.integer(0)), total};
}

ResponseOutcome StudyStore::storeOne(const ResponseInput& in) {
    std::int64_t participantId = 0;
    {
        SqliteStatement s = db_->prepare("SELECT id FROM participants WHERE token = ?");
        s.bind(1, in.token);
        if (!s.step()) throw RequestError(404, "unknown participant");
        participantId = s.integer(0);
    }
    // The reference must carry this participant's tag: another participant's trial (or a guessed number) is
    // indistinguishable from one that does not exist.
    TrialRecord trial;
    {
        const std::int64_t id = in.trialId & 0xFFFFFFFFll;
        const std::string unknown = "trial " + std::to_string(in.trialId) + ": unknown trial";
        if (in.trialId <= 0 || trialReference(in.token, id) != in.trialId) throw RequestError(404, unknown);
        SqliteStatement s = db_->prepare(std::string("SELECT ") + kTrialColumns + " FROM trials WHERE id = ?");
        s.bind(1, id);
        if (!s.step()) throw RequestError(404, unknown);
        trial = readTrial(s);
        if (trial.participantId != participantId) throw RequestError(404, unknown);
    }
    {
        SqliteStatement s = db_->prepare("SELECT participant_id FROM sessions WHERE id = ?");
        s.bind(1, in.sessionId);
        if (!s.step() || s.integer(0) != participantId)
            throw RequestError(404, "session " + std::to_string(in.sessionId) + ": unknown session");
    }
    const bool leftIsA = trial.plan.aOnLeft;
    const std::string chosen = (in.side == "left") == leftIsA ? "A" : "B";
    {
        SqliteStatement s = db_->prepare("SELECT chosen FROM responses WHERE trial_id = ?");
        s.bind(1, trial.id);
        if (s.step()) {
            // A re-send (lost acknowledgement, retry after a restart) is harmless; a different answer is not
            // allowed to replace the stored one.
            if (s.text(0) == chosen) return ResponseOutcome::duplicate;
            throw RequestError(409, "trial " + std::to_string(in.trialId) + ": already answered differently");
        }
    }
    {
        SqliteStatement s = db_->prepare("SELECT MIN(position) FROM trials WHERE participant_id = ?1 AND id NOT IN"
                                         " (SELECT trial_id FROM responses WHERE participant_id = ?1)");
        s.bind(1, participantId);
        s.step();
        if (s.isNull(0) || s.integer(0) != trial.position)
            throw RequestError(409, "trial " + std::to_string(in.trialId) +
                                        ": out of order (the next trial is at position " +
                                        (s.isNull(0) ? std::string("none") : std::to_string(s.integer(0))) + ")");
    }
    SqliteStatement insert = db_->prepare(
        "INSERT INTO responses (trial_id, participant_id, session_id, chosen, side, response_ms, client_time, "
        "server_time,"
        " viewport_width, viewport_height, device_pixel_ratio, user_agent) VALUES (?,?,?,?,?,?,?,?,?,?,?,?)");
    insert.bind(1, trial.id).bind(2, participantId).bind(3, in.sessionId).bind(4, chosen).bind(5, in.side);
    insert.bind(6, in.responseMs)
        .bind(7, validUtf8(in.clientTime, kMaxStoredText))
        .bind(8, utcTimestamp())
        .bind(9, in.viewportWidth);
    insert.bind(10, in.viewportHeight).bind(11, in.devicePixelRatio).bind(12, validUtf8(in.userAgent, kMaxStoredText));
    insert.run();
    if (in.conditions) {
        SqliteStatement c = db_->prepare(
            "INSERT INTO trial_conditions (trial_id, page_hidden, focus_lost, fullscreen) VALUES (?,?,?,?)");
        c.bind(1, trial.id).bind(2, in.conditions->pageHidden ? 1 : 0).bind(3, in.conditions->focusLost ? 1 : 0);
        c.bind(4, in.conditions->fullscreen ? 1 : 0);
        c.run();
    }
    if (definition_.design.activePairs && (trial.plan.kind == TrialKind::test || trial.plan.kind == TrialKind::repeat))
        for (std::size_t b = 0; b < definition_.blocks.size(); ++b) {
            const StudyBlock& block = definition_.blocks[b];
            if (block.name != trial.plan.block) continue;
            const auto a = std::find(block.conditions.begin(), block.conditions.end(), trial.plan.conditionA);
            const auto c = std::find(block.conditions.begin(), block.conditions.end(), trial.plan.conditionB);
            if (a == block.conditions.end() || c == block.conditions.end() || a == c) break;
            const int ia = static_cast<int>(a - block.conditions.begin()),
                      ic = static_cast<int>(c - block.conditions.begin());
            uncommittedAnswers_.push_back({b, std::min(ia, ic), std::max(ia, ic), (chosen == "A") == (ia < ic)});
            break;
        }
    return ResponseOutcome::stored;
}

ResponseOutcome StudyStore::recordResponse(const ResponseInput& in) {
    if (in.side != "left" && in.side != "right") throw RequestError(400, "side: expected \"left\" or \"right\"");
    PendingResponse mine;
    mine.input = &in;
    std::unique_lock queueLock(queueMutex_);
    queue_.push_back(&mine);
    while (!mine.done) {
        if (committing_) {
            queueChanged_.wait(queueLock);
            continue;
        }
        // This thread commits everything queued so far (its own response included).
        committing_ = true;
        std::vector<PendingResponse*> batch;
        batch.swap(queue_);
        queueLock.unlock();
        commitBatch(batch);
        queueLock.lock();
        committing_ = false;
        for (PendingResponse* p : batch) p->done = true;
        queueChanged_.notify_all();
    }
    if (mine.error) std::rethrow_exception(mine.error);
    return mine.outcome;
}

void StudyStore::commitBatch(const std::vector<PendingResponse*>& batch) {
    std::lock_guard lock(mutex_);
    try {
        SqliteTransaction tx(*db_);
        for (PendingResponse* p : batch) {
            // Validation only reads, and the insert is the last step, so a rejected response leaves nothing behind.
            try {
                p->outcome = storeOne(*p->input);
            } catch (const RequestError&) {
                p->error = std::current_exception();
            }
        }
        tx.commit();
        // The committed answers of an active design's test trials join their blocks' counts.
        if (activeCountsLoaded_)
            for (const ActiveAnswer& a : uncommittedAnswers_) {
                BlockAnswers& answers = activeAnswers_[a.block];
                auto& entry = answers.counts[{a.i, a.j}];
                (a.iWon ? entry.first : entry.second) += 1.0;
                ++answers.generation;
            }
        uncommittedAnswers_.clear();
    } catch (...) {
        uncommittedAnswers_.clear();
        // Nothing of this batch was committed: every response not already rejected fails (and is re-sent).
        for (PendingResponse* p : batch)
            if (!p->error) p->error = std::current_exception();
    }
}

std::vector<ParticipantStatus> StudyStore::status() {
    std::lock_guard lock(mutex_);
    SqliteTransaction tx(*db_, false); // one consistent snapshot
    std::vector<ParticipantStatus> out;
    SqliteStatement s =
        db_->prepare(std::string("SELECT ") + kParticipantColumns +
                     ", (SELECT COUNT(*) FROM trials t WHERE t.participant_id = p.id)"
                     ", (SELECT COUNT(*) FROM responses r WHERE r.participant_id = p.id)"
                     ", (SELECT COUNT(*) FROM responses r JOIN trials t ON t.id = r.trial_id WHERE r.participant_id = "
                     "p.id AND t.kind IN ('test','repeat'))"
                     ", (SELECT COUNT(*) FROM responses r JOIN trials t ON t.id = r.trial_id WHERE r.participant_id = "
                     "p.id AND t.kind = 'catch')"
                     ", (SELECT COUNT(*) FROM responses r JOIN trials t ON t.id = r.trial_id WHERE r.participant_id = "
                     "p.id AND t.kind = 'catch' AND r.chosen = t.expected)"
                     ", (SELECT COALESCE(MAX(server_time), '') FROM responses r WHERE r.participant_id = p.id)"
                     ", rec.platform, rec.external_id, rec.external_study_id, rec.external_session_id"
                     " FROM participants p LEFT JOIN recruitment rec ON rec.participant_id = p.id ORDER BY p.id");
    while (s.step()) {
        ParticipantStatus st;
        st.participant = readParticipant(s);
        st.progress.total = definition_.design.activePairs ? plannedTrialCount() : static_cast<int>(s.integer(7));
        st.progress.answered = static_cast<int>(s.integer(8));
        st.testAnswered = static_cast<int>(s.integer(9));
        st.catchAnswered = static_cast<int>(s.integer(10));
        st.catchCorrect = static_cast<int>(s.integer(11));
        st.lastResponseAt = s.text(12);
        if (!s.isNull(13)) st.external = ExternalIds{s.text(13), s.text(14), s.text(15), s.text(16)};
        out.push_back(std::move(st));
    }
    return out;
}

namespace {

constexpr const char* kViewingColumns =
    "v.screen_width, v.screen_height, v.screen_width_px, v.screen_height_px, v.colour_depth, v.fullscreen,"
    " v.pointer_fine, v.touch_points, v.mobile, v.pixels_per_mm, v.viewing_distance_mm, v.pixels_per_degree";

// The kViewingColumns starting at `first` (NULL session_id of the LEFT JOIN: not reported).
std::optional<ViewingConditions> readViewing(const SqliteStatement& s, int first, double devicePixelRatio,
                                             int viewportWidth, int viewportHeight) {
    if (s.isNull(first)) return std::nullopt;
    ViewingConditions v;
    v.screenWidth = static_cast<int>(s.integer(first));
    v.screenHeight = static_cast<int>(s.integer(first + 1));
    v.screenWidthPx = static_cast<int>(s.integer(first + 2));
    v.screenHeightPx = static_cast<int>(s.integer(first + 3));
    v.colourDepth = static_cast<int>(s.integer(first + 4));
    v.fullscreen = s.integer(first + 5) != 0;
    v.pointerFine = s.integer(first + 6) != 0;
    v.touchPoints = static_cast<int>(s.integer(first + 7));
    v.mobile = s.integer(first + 8) != 0;
    if (!s.isNull(first + 9)) v.pixelsPerMm = s.real(first + 9);
    if (!s.isNull(first + 10)) v.viewingDistanceMm = s.real(first + 10);
    if (!s.isNull(first + 11)) v.pixelsPerDegree = s.real(first + 11);
    v.devicePixelRatio = devicePixelRatio;
    v.viewportWidth = viewportWidth;
    v.viewportHeight = viewportHeight;
    return v;
}

} // namespace

std::vector<ResponseRow> StudyStore::responses() {
    std::lock_guard lock(mutex_);
    SqliteStatement s = db_->prepare(
        std::string(
            "SELECT p.label, p.id, t.id, t.position, t.kind, t.block, t.condition_a, t.condition_b, sa.stimulus,"
            " COALESCE(sb.stimulus, 'blank'), t.a_on_left, r.chosen, t.expected, r.response_ms, r.client_time,"
            " r.server_time, r.viewport_width, r.viewport_height, r.device_pixel_ratio, r.user_agent, r.session_id,"
            " c.page_hidden, c.focus_lost, c.fullscreen, ses.device_pixel_ratio, ses.viewport_width, "
            "ses.viewport_height,"
            " rec.platform, rec.external_id, rec.external_study_id, rec.external_session_id, ") +
        kViewingColumns +
        " FROM responses r JOIN trials t ON t.id = r.trial_id JOIN participants p ON p.id = t.participant_id"
        " JOIN stimuli sa ON sa.id = t.stimulus_a LEFT JOIN stimuli sb ON sb.id = t.stimulus_b"
        " JOIN sessions ses ON ses.id = r.session_id LEFT JOIN trial_conditions c ON c.trial_id = r.trial_id"
        " LEFT JOIN recruitment rec ON rec.participant_id = p.id LEFT JOIN viewing_conditions v ON v.session_id = "
        "r.session_id"
        " ORDER BY p.id, t.position");
    std::vector<ResponseRow> out;
    while (s.step()) {
        ResponseRow r;
        r.observer = s.text(0);
        r.participantId = s.integer(1);
        r.trialId = s.integer(2);
        r.position = static_cast<int>(s.integer(3));
        r.kind = trialKindFromName(s.text(4));
        r.scene = s.text(5);
        r.conditionA = s.text(6);
        r.conditionB = s.text(7);
        r.stimulusA = s.text(8);
        r.stimulusB = s.text(9);
        r.aOnLeft = s.integer(10) != 0;
        r.aSelected = s.text(11) == "A";
        if (r.kind == TrialKind::catchTrial) r.correct = s.text(11) == s.text(12);
        r.responseMs = s.real(13);
        r.clientTime = s.text(14);
        r.serverTime = s.text(15);
        r.viewportWidth = static_cast<int>(s.integer(16));
        r.viewportHeight = static_cast<int>(s.integer(17));
        r.devicePixelRatio = s.real(18);
        r.userAgent = s.text(19);
        r.sessionId = s.integer(20);
        if (!s.isNull(21)) r.conditions = TrialConditions{s.integer(21) != 0, s.integer(22) != 0, s.integer(23) != 0};
        r.sessionDevicePixelRatio = s.real(24);
        r.viewing = readViewing(s, 31, r.sessionDevicePixelRatio, static_cast<int>(s.integer(25)),
                                static_cast<int>(s.integer(26)));
        if (!s.isNull(27)) r.external = ExternalIds{s.text(27), s.text(28), s.text(29), s.text(30)};
        out.push_back(std::move(r));
    }
    return out;
}

std::vector<ResponseRow> StudyStore::flaggedTrials() {
    std::vector<ResponseRow> rows = responses();
    std::erase_if(rows, [](const ResponseRow& r) { return !r.flagged(); });
    return rows;
}

std::vector<SessionViewing> StudyStore::viewingConditions() {
    std::lock_guard lock(mutex_);
    SqliteStatement s =
        db_->prepare(std::string("SELECT p.label, p.id, ses.id, ses.started_at, ses.user_agent, ses.viewport_width,"
                                 " ses.viewport_height, ses.device_pixel_ratio, ") +
                     kViewingColumns +
                     " FROM sessions ses JOIN participants p ON p.id = ses.participant_id"
                     " LEFT JOIN viewing_conditions v ON v.session_id = ses.id ORDER BY ses.id");
    std::vector<SessionViewing> out;
    while (s.step()) {
        SessionViewing v;
        v.observer = s.text(0);
        v.participantId = s.integer(1);
        v.sessionId = s.integer(2);
        v.startedAt = s.text(3);
        v.userAgent = s.text(4);
        v.viewportWidth = static_cast<int>(s.integer(5));
        v.viewportHeight = static_cast<int>(s.integer(6));
        v.devicePixelRatio = s.real(7);
        v.viewing = readViewing(s, 8, v.devicePixelRatio, v.viewportWidth, v.viewportHeight);
        out.push_back(std::move(v));
    }
    return out;
}

std::int64_t StudyStore::responseCount() {
    std::lock_guard lock(mutex_);
    SqliteStatement s = db_->prepare("SELECT COUNT(*) FROM responses");
    s.step();
    return s.integer(0);
}

} // namespace skinlab::experiments
