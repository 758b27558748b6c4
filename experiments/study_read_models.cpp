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
    const int planned = connection_.definition.design.activePairs ? plannedTrialCount() : 0;
    std::vector<ParticipantStatus> out;
    SqliteStatement s = connection_.db->prepare(participantStatusQuery());
    while (s.step()) out.push_back(readParticipantStatus(s, planned));
    return out;
}

std::vector<ResponseRow> StudyReadModels::responses() {
    std::lock_guard lock(connection_.mutex);
    SqliteStatement s = connection_.db->prepare(responseRowsQuery());
    std::vector<ResponseRow> out;
    while (s.step()) out.push_back(readResponseRow(s));
    return out;
}

std::vector<ResponseRow> StudyReadModels::flaggedTrials() {
    std::vector<ResponseRow> rows = responses();
    std::erase_if(rows, [](const ResponseRow& r) { return !r.flagged.value_or(false); });
    return rows;
}

std::vector<SessionViewing> StudyReadModels::viewingConditions() {
    std::lock_guard lock(connection_.mutex);
    SqliteStatement s = connection_.db->prepare(sessionViewingsQuery());
    std::vector<SessionViewing> out;
    while (s.step()) out.push_back(readSessionViewing(s));
    return out;
}

std::int64_t StudyReadModels::responseCount() {
    std::lock_guard lock(connection_.mutex);
    SqliteStatement s = connection_.db->prepare("SELECT COUNT(*) FROM responses");
    s.step();
    return s.integer(0);
}

} // namespace skinlab::experiments
