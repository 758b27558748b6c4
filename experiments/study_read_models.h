#pragma once
// What the study file answers when read: a participant's progress, trials and first unanswered trial, and the
// researcher's views (status per participant, every response joined with its trial, session viewing conditions).
// Each call takes the connection's mutex (firstUnanswered: held by the caller; simulatedLabels: called before
// serving, takes none).
#include "experiments/study_records.h"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace skinlab::experiments {

struct StudyConnection;

class StudyReadModels {
public:
    explicit StudyReadModels(StudyConnection& connection) : connection_(connection) {}

    // Labels of the participants `study simulate` sent (their join keys say so), in joining order.
    std::vector<std::string> simulatedLabels() const;
    Progress progress(std::int64_t participantId);
    std::vector<TrialRecord> trials(std::int64_t participantId);
    // The connection's mutex held: the participant's first unanswered stored trial, if any.
    std::optional<TrialRecord> firstUnanswered(std::int64_t participantId);

    std::vector<ParticipantStatus> status();
    std::vector<ResponseRow> responses();
    std::vector<ResponseRow> flaggedTrials();
    std::vector<SessionViewing> viewingConditions();
    std::int64_t responseCount();

private:
    // An active design stores its test trials batch by batch; its length per participant is known from the design.
    int plannedTrialCount() const;

    StudyConnection& connection_;
};

} // namespace skinlab::experiments
