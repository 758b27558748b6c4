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
