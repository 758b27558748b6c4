#include "experiments/study_store.h"

#include "experiments/active_design_state.h"
#include "experiments/response_queue.h"
#include "experiments/sqlite_database.h"
#include "experiments/study_connection.h"
#include "experiments/study_participants.h"
#include "experiments/study_read_models.h"
#include "experiments/study_schema.h"

namespace skinlab::experiments {
namespace fs = std::filesystem;

void StudyStore::create(const fs::path& path, const StudyDefinition& definition, const std::string& designText,
                        const StimulusManifest& manifest) {
    createStudyFile(path, definition, designText, manifest);
}

StudyStore::StudyStore(const fs::path& path, StudyAccess access) : connection_(std::make_unique<StudyConnection>()) {
    OpenedStudyFile file = openStudyFile(path, access);
    connection_->path = path;
    connection_->db = std::move(file.db);
    connection_->definition = std::move(file.definition);
    active_ = std::make_unique<ActiveDesignState>(*connection_);
    participants_ = std::make_unique<ParticipantRegistry>(*connection_);
    responses_ = std::make_unique<ResponseQueue>(*connection_, *active_);
    reads_ = std::make_unique<StudyReadModels>(*connection_);
}

StudyStore::~StudyStore() = default;

const StudyDefinition& StudyStore::definition() const { return connection_->definition; }
const fs::path& StudyStore::path() const { return connection_->path; }

std::string StudyStore::meta(const std::string& key) const {
    return studyMeta(*connection_->db, connection_->path, key);
}

std::vector<std::string> StudyStore::simulatedLabels() const { return reads_->simulatedLabels(); }

ParticipantRecord StudyStore::join(const std::string& requestedLabel, const std::string& joinKey,
                                   const std::optional<ExternalIds>& external,
                                   const std::optional<ClientOrigin>& origin) {
    bool created = false;
    ParticipantRecord p = participants_->join(requestedLabel, joinKey, external, origin, created);
    // Active design: the first stretch (practice trials, the first batch) is planned outside the lock and stored
    // before the join is answered. Should the process die in between, the participant's first nextTrial() plans it.
    if (created && connection_->definition.design.activePairs) active_->extendPlan(p.id);
    return p;
}

ParticipantRecord StudyStore::participant(const std::string& token) { return participants_->participant(token); }

std::int64_t StudyStore::startSession(std::int64_t participantId, const std::string& userAgent, int viewportWidth,
                                      int viewportHeight, double devicePixelRatio,
                                      const std::optional<ViewingConditions>& viewing, int maxSessions,
                                      const std::optional<ClientOrigin>& origin) {
    return participants_->startSession(participantId, userAgent, viewportWidth, viewportHeight, devicePixelRatio,
                                       viewing, maxSessions, origin);
}

void StudyStore::recordJoinAddress(std::int64_t participantId, const std::string& address, const std::string& source) {
    participants_->recordJoinAddress(participantId, address, source);
}

std::optional<TrialRecord> StudyStore::nextTrial(std::int64_t participantId) {
    for (;;) {
        {
            std::lock_guard lock(connection_->mutex);
            std::optional<TrialRecord> next = reads_->firstUnanswered(participantId);
            if (next || !connection_->definition.design.activePairs) return next;
        }
        // Active design: every stored trial answered, so the next batch is planned and stored now (before it is
        // shown). When another request of the same participant stored one meanwhile, look again.
        if (active_->extendPlan(participantId) == ActiveDesignState::Extension::complete) {
            // The plan is complete — possibly because a concurrent request stored its last batch after the look
            // above, so its trials may still be unanswered: look once more.
            std::lock_guard lock(connection_->mutex);
            return reads_->firstUnanswered(participantId);
        }
    }
}

Progress StudyStore::progress(std::int64_t participantId) { return reads_->progress(participantId); }

ResponseOutcome StudyStore::recordResponse(const ResponseInput& input) { return responses_->record(input); }

std::vector<ParticipantStatus> StudyStore::status() { return reads_->status(); }
std::vector<ResponseRow> StudyStore::responses() { return reads_->responses(); }
std::vector<SessionViewing> StudyStore::viewingConditions() { return reads_->viewingConditions(); }
std::vector<ResponseRow> StudyStore::flaggedTrials() { return reads_->flaggedTrials(); }
std::vector<TrialRecord> StudyStore::trials(std::int64_t participantId) { return reads_->trials(participantId); }
std::int64_t StudyStore::responseCount() { return reads_->responseCount(); }

} // namespace skinlab::experiments
