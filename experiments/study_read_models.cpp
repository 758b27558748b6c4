#include "experiments/study_read_models.h"

#include "experiments/study_connection.h"
#include "experiments/study_rows.h"

namespace skinlab::experiments {

std::vector<std::string> StudyReadModels::simulatedLabels() const {
    // simulatedJoinKey(): "sim-" and 40 hexadecimal digits.
    SqliteStatement s = connection_.db->prepare("SELECT label FROM participants WHERE join_key LIKE 'sim-%' AND "
                                                "length(join_key) = 44 ORDER BY participant_index");
    std::vector<std::string> labels;
    while (s.step()) labels.push_back(s.text(0));
    return labels;
}

int StudyReadModels::plannedTrialCount() const {
    const StudyDefinition& d = connection_.definition;
    return d.design.practiceTrials + d.testTrialCount() + d.repeatTrialCount() + d.catchTrialCount();
}

std::vector<TrialRecord> StudyReadModels::trials(std::int64_t participantId) {
    std::lock_guard lock(connection_.mutex);
    SqliteStatement s = connection_.db->prepare(std::string("SELECT ") + kTrialColumns +
                                                " FROM trials WHERE participant_id = ? ORDER BY position");
    s.bind(1, participantId);
    std::vector<TrialRecord> out;
    while (s.step()) out.push_back(readTrial(s));
    return out;
}

Progress StudyReadModels::progress(std::int64_t participantId) {
    std::lock_guard lock(connection_.mutex);
    SqliteStatement s = connection_.db->prepare("SELECT (SELECT COUNT(*) FROM responses WHERE participant_id = ?1),"
                                                " (SELECT COUNT(*) FROM trials WHERE participant_id = ?1)");
    s.bind(1, participantId);
    s.step();
    // An active design stores its test trials batch by batch; its length is known from the design.
    const int total = connection_.definition.design.activePairs ? plannedTrialCount() : static_cast<int>(s.integer(1));
    return {static_cast<int>(s.integer(0)), total};
}

std::optional<TrialRecord> StudyReadModels::firstUnanswered(std::int64_t participantId) {
    SqliteStatement s =
        connection_.db->prepare(std::string("SELECT ") + kTrialColumns +
                                " FROM trials WHERE participant_id = ? AND id NOT IN"
                                " (SELECT trial_id FROM responses WHERE participant_id = ?) ORDER BY position LIMIT 1");
    s.bind(1, participantId).bind(2, participantId);
    if (!s.step()) return std::nullopt;
    return readTrial(s);
}

std::vector<ParticipantStatus> StudyReadModels::status() {
    std::lock_guard lock(connection_.mutex);
    SqliteTransaction tx(*connection_.db, false); // one consistent snapshot
    std::vector<ParticipantStatus> out;
    SqliteStatement s = connection_.db->prepare(
        std::string("SELECT ") + kParticipantColumns +
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
        st.progress.total =
            connection_.definition.design.activePairs ? plannedTrialCount() : static_cast<int>(s.integer(7));
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

std::vector<ResponseRow> StudyReadModels::responses() {
    std::lock_guard lock(connection_.mutex);
    SqliteStatement s = connection_.db->prepare(
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

std::vector<ResponseRow> StudyReadModels::flaggedTrials() {
    std::vector<ResponseRow> rows = responses();
    std::erase_if(rows, [](const ResponseRow& r) { return !r.flagged(); });
    return rows;
}

std::vector<SessionViewing> StudyReadModels::viewingConditions() {
    std::lock_guard lock(connection_.mutex);
    SqliteStatement s = connection_.db->prepare(
        std::string("SELECT p.label, p.id, ses.id, ses.started_at, ses.user_agent, ses.viewport_width,"
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

std::int64_t StudyReadModels::responseCount() {
    std::lock_guard lock(connection_.mutex);
    SqliteStatement s = connection_.db->prepare("SELECT COUNT(*) FROM responses");
    s.step();
    return s.integer(0);
}

} // namespace skinlab::experiments
