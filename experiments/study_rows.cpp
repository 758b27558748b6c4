#include "experiments/study_rows.h"

namespace skinlab::experiments {

void insertTrials(SqliteDatabase& db, std::int64_t participantId, const std::vector<PlannedTrial>& plan,
                  int firstPosition) {
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

} // namespace skinlab::experiments

namespace skinlab::experiments {

std::string responseRowsQuery() {
    return std::string(
               "SELECT p.label, p.id, t.id, t.position, t.kind, t.block, t.condition_a, t.condition_b, sa.stimulus,"
               " COALESCE(sb.stimulus, 'blank'), t.a_on_left, r.chosen, t.expected, r.response_ms, r.client_time,"
               " r.server_time, r.viewport_width, r.viewport_height, r.device_pixel_ratio, r.user_agent, r.session_id,"
               " c.page_hidden, c.focus_lost, c.fullscreen, ses.device_pixel_ratio, ses.viewport_width,"
               " ses.viewport_height, rec.platform, rec.external_id, rec.external_study_id, "
               "rec.external_session_id, ") +
           kViewingColumns + ", " + kCorrectSql + ", " + kFlaggedSql +
           " FROM responses r JOIN trials t ON t.id = r.trial_id JOIN participants p ON p.id = t.participant_id"
           " JOIN stimuli sa ON sa.id = t.stimulus_a LEFT JOIN stimuli sb ON sb.id = t.stimulus_b"
           " JOIN sessions ses ON ses.id = r.session_id LEFT JOIN trial_conditions c ON c.trial_id = r.trial_id"
           " LEFT JOIN recruitment rec ON rec.participant_id = p.id"
           " LEFT JOIN viewing_conditions v ON v.session_id = r.session_id"
           // = p.id, t.position, in the order of the trials' (participant_id, position) index: no sort, so the
           // rows stream out as they are read, whatever the study's size.
           " ORDER BY t.participant_id, t.position";
}

ResponseRow readResponseRow(const SqliteStatement& s) {
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
    r.viewing =
        readViewing(s, 31, r.sessionDevicePixelRatio, static_cast<int>(s.integer(25)), static_cast<int>(s.integer(26)));
    if (!s.isNull(27)) r.external = ExternalIds{s.text(27), s.text(28), s.text(29), s.text(30)};
    if (!s.isNull(43)) r.correct = s.integer(43) != 0;
    if (!s.isNull(44)) r.flagged = s.integer(44) != 0;
    return r;
}

std::string sessionViewingsQuery() {
    return std::string("SELECT p.label, p.id, ses.id, ses.started_at, ses.user_agent, ses.viewport_width,"
                       " ses.viewport_height, ses.device_pixel_ratio, ") +
           kViewingColumns +
           " FROM sessions ses JOIN participants p ON p.id = ses.participant_id"
           " LEFT JOIN viewing_conditions v ON v.session_id = ses.id ORDER BY ses.id";
}

SessionViewing readSessionViewing(const SqliteStatement& s) {
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
    return v;
}

std::string participantStatusQuery() {
    return std::string("SELECT ") + kParticipantColumns +
           ", (SELECT COUNT(*) FROM trials t WHERE t.participant_id = p.id)"
           ", (SELECT COUNT(*) FROM responses r WHERE r.participant_id = p.id)"
           ", (SELECT COUNT(*) FROM responses r JOIN trials t ON t.id = r.trial_id WHERE r.participant_id = "
           "p.id AND t.kind IN ('test','repeat'))"
           ", (SELECT COUNT(*) FROM responses r JOIN trials t ON t.id = r.trial_id WHERE r.participant_id = "
           "p.id AND t.kind = 'catch')"
           ", (SELECT COUNT(*) FROM responses r JOIN trials t ON t.id = r.trial_id WHERE r.participant_id = "
           "p.id AND " +
           kCorrectSql + " = 1)" +
           ", (SELECT COALESCE(MAX(server_time), '') FROM responses r WHERE r.participant_id = p.id)"
           ", rec.platform, rec.external_id, rec.external_study_id, rec.external_session_id"
           " FROM participants p LEFT JOIN recruitment rec ON rec.participant_id = p.id ORDER BY p.id";
}

ParticipantStatus readParticipantStatus(const SqliteStatement& s, int plannedTotal) {
    ParticipantStatus st;
    st.participant = readParticipant(s);
    st.progress.total = plannedTotal > 0 ? plannedTotal : static_cast<int>(s.integer(7));
    st.progress.answered = static_cast<int>(s.integer(8));
    st.testAnswered = static_cast<int>(s.integer(9));
    st.catchAnswered = static_cast<int>(s.integer(10));
    st.catchCorrect = static_cast<int>(s.integer(11));
    st.lastResponseAt = s.text(12);
    if (!s.isNull(13)) st.external = ExternalIds{s.text(13), s.text(14), s.text(15), s.text(16)};
    return st;
}

} // namespace skinlab::experiments
