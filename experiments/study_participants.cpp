#include "experiments/study_participants.h"

#include "common/time.h"
#include "experiments/study_connection.h"
#include "experiments/study_errors.h"
#include "experiments/study_rows.h"
#include "experiments/study_text.h"

#include <cstdio>

namespace skinlab::experiments {

void ParticipantRegistry::recordJoinAddress(std::int64_t participantId, const std::string& address,
                                            const std::string& source) {
    std::lock_guard lock(connection_.mutex);
    SqliteStatement s =
        connection_.db->prepare("INSERT OR IGNORE INTO participant_addresses (participant_id, client_address, source,"
                                " recorded_at) VALUES (?,?,?,?)");
    s.bind(1, participantId).bind(2, validUtf8(address, 64)).bind(3, source).bind(4, utcTimestamp());
    s.run();
}

void ParticipantRegistry::insertVisit(std::int64_t participantId, const char* outcome, const ClientOrigin& origin) {
    SqliteStatement s =
        connection_.db->prepare("INSERT INTO participant_visits (participant_id, outcome, client_address, source,"
                                " recorded_at) VALUES (?,?,?,?,?)");
    s.bind(1, participantId).bind(2, std::string(outcome)).bind(3, validUtf8(origin.address, 64));
    s.bind(4, origin.source).bind(5, utcTimestamp());
    s.run();
}

int ParticipantRegistry::visitCount(std::int64_t participantId, const char* outcome) {
    SqliteStatement s =
        connection_.db->prepare("SELECT COUNT(*) FROM participant_visits WHERE participant_id = ? AND outcome = ?");
    s.bind(1, participantId).bind(2, outcome);
    s.step();
    return static_cast<int>(s.integer(0));
}

ParticipantRecord ParticipantRegistry::join(const std::string& requestedLabel, const std::string& joinKey,
                                            const std::optional<ExternalIds>& external,
                                            const std::optional<ClientOrigin>& origin, bool& created) {
    std::lock_guard lock(connection_.mutex);
    SqliteDatabase& db = *connection_.db;
    SqliteTransaction tx(db);
    // A returning participant: recorded (address, time) with every resume; bounded per participant, counting its own
    // resumes only (refused attempts by others never use them up).
    auto resume = [&](ParticipantRecord existing) {
        if (origin) {
            if (visitCount(existing.id, "resumed") >= kMaxVisitsPerParticipant)
                throw LimitReached("this participant has resumed too often; contact the researcher");
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
        SqliteStatement s = db.prepare(std::string("SELECT ") + kParticipantColumns +
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
            if (origin && visitCount(existing.id, "refused") < kMaxVisitsPerParticipant) {
                insertVisit(existing.id, "refused", *origin);
                tx.commit();
            }
            const std::string parameter = platformParameters(connection_.definition.design.recruitment).id;
            throw Conflict(parameter + ": this " + external->platform +
                           " id has already started this study in another browser or from another "
                           "link; continue where you started (same browser, same link), or contact "
                           "the researcher");
        }
    }
    if (!joinKey.empty()) {
        SqliteStatement s =
            db.prepare(std::string("SELECT ") + kParticipantColumns + " FROM participants WHERE join_key = ?");
        s.bind(1, joinKey);
        if (s.step()) {
            ParticipantRecord existing = readParticipant(s);
            s.reset();
            // A join key belongs to one participant: not to another label, nor to another platform id.
            if ((!requestedLabel.empty() && existing.label != requestedLabel) || external)
                throw Conflict("join_key: already used by another participant");
            return resume(existing);
        }
    }
    ParticipantRecord p = insertParticipant(requestedLabel, joinKey, external, origin);
    tx.commit();
    created = true;
    return p;
}

ParticipantRecord ParticipantRegistry::insertParticipant(const std::string& requestedLabel, const std::string& joinKey,
                                                         const std::optional<ExternalIds>& external,
                                                         const std::optional<ClientOrigin>& origin) {
    SqliteDatabase& db = *connection_.db;
    const StudyDefinition& definition = connection_.definition;
    ParticipantRecord p;
    {
        SqliteStatement count = db.prepare("SELECT COALESCE(MAX(participant_index) + 1, 0) FROM participants");
        count.step();
        p.index = count.integer(0);
    }
    if (!requestedLabel.empty()) {
        SqliteStatement taken = db.prepare("SELECT 1 FROM participants WHERE label = ?");
        taken.bind(1, requestedLabel);
        if (taken.step())
            throw Conflict("participant label \"" + requestedLabel +
                           "\" is already taken; open that participant's link to resume");
    }
    if (requestedLabel.empty()) {
        // The default label follows the joining order, skipping labels already taken (an explicit label may equal a
        // later default one: "P007" joined by hand must not lock out every bare join after P006).
        SqliteStatement taken = db.prepare("SELECT 1 FROM participants WHERE label = ?");
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
    p.seed = participantSeed(definition.design.seed, p.index);
    p.completionCode = makeCompletionCode();
    p.createdAt = utcTimestamp();
    SqliteStatement insert = db.prepare(
        "INSERT INTO participants (participant_index, label, token, join_key, seed, completion_code, created_at)"
        " VALUES (?,?,?,?,?,?,?)");
    insert.bind(1, p.index).bind(2, p.label).bind(3, p.token);
    if (joinKey.empty()) insert.bindNull(4);
    else insert.bind(4, joinKey);
    insert.bind(5, static_cast<std::int64_t>(p.seed)).bind(6, p.completionCode).bind(7, p.createdAt);
    insert.run();
    p.id = db.lastInsertId();
    if (external) {
        SqliteStatement ids = db.prepare("INSERT INTO recruitment (participant_id, platform, external_id,"
                                         " external_study_id, external_session_id) VALUES (?,?,?,?,?)");
        ids.bind(1, p.id).bind(2, external->platform).bind(3, external->id).bind(4, external->study);
        ids.bind(5, external->session);
        ids.run();
    }
    if (origin) {
        SqliteStatement a = db.prepare("INSERT OR IGNORE INTO participant_addresses (participant_id, client_address,"
                                       " source, recorded_at) VALUES (?,?,?,?)");
        a.bind(1, p.id).bind(2, validUtf8(origin->address, 64)).bind(3, origin->source).bind(4, p.createdAt);
        a.run();
    }
    if (!definition.design.activePairs) insertTrials(db, p.id, planTrials(definition, p.index, p.seed));
    return p;
}

ParticipantRecord ParticipantRegistry::participant(const std::string& token) {
    std::lock_guard lock(connection_.mutex);
    SqliteStatement s =
        connection_.db->prepare(std::string("SELECT ") + kParticipantColumns + " FROM participants WHERE token = ?");
    s.bind(1, token);
    if (!s.step()) throw NotFound("unknown participant");
    return readParticipant(s);
}

std::int64_t ParticipantRegistry::startSession(std::int64_t participantId, const std::string& userAgent,
                                               int viewportWidth, int viewportHeight, double devicePixelRatio,
                                               const std::optional<ViewingConditions>& viewing, int maxSessions,
                                               const std::optional<ClientOrigin>& origin) {
    std::lock_guard lock(connection_.mutex);
    SqliteDatabase& db = *connection_.db;
    SqliteTransaction tx(db);
    if (maxSessions > 0) {
        // Each page load starts a session: a handful per participant is normal, thousands are a flood.
        SqliteStatement count = db.prepare("SELECT COUNT(*) FROM sessions WHERE participant_id = ?");
        count.bind(1, participantId);
        count.step();
        if (count.integer(0) >= maxSessions)
            throw LimitReached("too many sessions for this participant (at most " + std::to_string(maxSessions) +
                               "); contact the researcher");
    }
    SqliteStatement s = db.prepare("INSERT INTO sessions (participant_id, started_at, user_agent, viewport_width, "
                                   "viewport_height, device_pixel_ratio)"
                                   " VALUES (?,?,?,?,?,?)");
    s.bind(1, participantId)
        .bind(2, utcTimestamp())
        .bind(3, validUtf8(userAgent, kMaxStoredText))
        .bind(4, viewportWidth);
    s.bind(5, viewportHeight);
    s.bind(6, devicePixelRatio);
    s.run();
    const std::int64_t session = db.lastInsertId();
    if (viewing) {
        const ViewingConditions& v = *viewing;
        SqliteStatement c = db.prepare(
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

} // namespace skinlab::experiments
