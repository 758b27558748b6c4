#pragma once
// study.db: one SQLite file (WAL journal, synchronous=FULL) holding the design, the stimulus manifest and its
// hash, participants, sessions, planned trials and responses. Schema: docs/experiments.md ("The study file").
//
// Crash safety: each response is validated and inserted inside an IMMEDIATE transaction (responses arriving
// together share one: group commit), and recordResponse() returns only after COMMIT, which with WAL +
// synchronous=FULL means the WAL frame is fsynced. The server acknowledges after that, so an acknowledged response
// survives kill -9 and power loss. A response is keyed by its trial (PRIMARY KEY), so a re-sent response can never
// be stored twice.
//
// StudyStore is the facade over the study file's parts, each in its own file: the schema (study_schema.h),
// participants and sessions (study_participants.h), the group commit of responses (response_queue.h), an active
// design's counts and plan extension (active_design_state.h) and the read models (study_read_models.h); they share
// one connection and its mutex (study_connection.h). A refused request throws a StudyRefusal
// (experiments/study_errors.h: NotFound, Conflict, LimitReached, InvalidValue), never an HTTP status.
#include "analysis/scaling/active_sampling.h"
#include "experiments/recruitment.h"
#include "experiments/study_definition.h"
#include "experiments/study_errors.h"
#include "experiments/study_records.h"
#include "experiments/study_text.h"
#include "experiments/trial_plan.h"
#include "experiments/viewing_conditions.h"

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace skinlab::experiments {

struct StudyConnection;
class ActiveDesignState;
class ParticipantRegistry;
class ResponseQueue;
class StudyReadModels;

class StudyStore {
public:
    // Writes a new study file atomically (built under a temporary name, then renamed). Refuses to overwrite an
    // existing file: a study holds responses that must never be lost by a repeated `create`.
    static void create(const std::filesystem::path& path, const StudyDefinition& definition,
                       const std::string& designText, const StimulusManifest& manifest);

    // readWrite (serving): a file or folder this process cannot write is refused (InputError) at once. readOnly: the
    // file is only read (also on a read-only mount); any write is refused by SQLite.
    explicit StudyStore(const std::filesystem::path& path, StudyAccess access = StudyAccess::readWrite);
    ~StudyStore();

    const StudyDefinition& definition() const;
    const std::filesystem::path& path() const;
    std::string meta(const std::string& key) const;
    // Labels of the participants `study simulate` sent (their join keys say so), in joining order.
    std::vector<std::string> simulatedLabels() const;

    // A new participant with a fresh token, seed and planned trials (one transaction). `label` empty = "P001"...
    // `joinKey` (a secret chosen by the client, may be empty) makes joining idempotent: a retried join whose first
    // answer was lost returns the participant it created. Throws Conflict when the label is taken.
    // `external` (a recruitment platform's ids, normalised): one platform id is one participant. A join with a known
    // platform id resumes that participant only with something only that participant's browser holds: the join key
    // of its first join, or the platform's per-attempt session id (Prolific SESSION_ID, MTurk assignmentId) it first
    // joined with; the platform id alone never does. Otherwise Conflict, and the refused attempt is recorded.
    // `origin`: stored with a new participant (participant_addresses) and with every resume or refused attempt
    // (participant_visits); a participant resumed kMaxVisitsPerParticipant times is refused (LimitReached).
    ParticipantRecord join(const std::string& label, const std::string& joinKey = "",
                           const std::optional<ExternalIds>& external = std::nullopt,
                           const std::optional<ClientOrigin>& origin = std::nullopt);
    // Throws NotFound for an unknown token.
    ParticipantRecord participant(const std::string& token);
    // `viewing` (when the page reported it) is stored with the session. A participant who already has
    // `maxSessions` sessions (0 = no limit) is refused with LimitReached and nothing is stored. `origin`: recorded
    // with the session (participant_visits, outcome "session"): every page load of a participation has its address.
    std::int64_t startSession(std::int64_t participantId, const std::string& userAgent, int viewportWidth,
                              int viewportHeight, double devicePixelRatio,
                              const std::optional<ViewingConditions>& viewing = std::nullopt,
                              int maxSessions = kDefaultSessionsPerParticipant,
                              const std::optional<ClientOrigin>& origin = std::nullopt);
    // The first unanswered trial, if any. For an active design whose stored trials are all answered, the next
    // batch is planned from the current answers and stored first (see experiments/active_plan.h).
    std::optional<TrialRecord> nextTrial(std::int64_t participantId);
    // The client address a participant joined from (table participant_addresses; the first one is kept when a
    // retried join returns the same participant). `source`: "peer" (the TCP peer) or "forwarded" (by a trusted
    // proxy, X-Forwarded-For).
    void recordJoinAddress(std::int64_t participantId, const std::string& address, const std::string& source);
    Progress progress(std::int64_t participantId);
    // Validates and commits one response (see the header comment). Refusals: InvalidValue (side), NotFound
    // (participant, trial or session; another participant's trial or session is unknown too: no answer tells whose
    // it is), Conflict (out of order, or a different answer to an already answered trial).
    ResponseOutcome recordResponse(const ResponseInput& input);

    std::vector<ParticipantStatus> status();
    std::vector<ResponseRow> responses();
    // Every session's viewing conditions, in order of starting (the researcher's overview).
    std::vector<SessionViewing> viewingConditions();
    // The responses to trials during which the page was hidden or lost the focus.
    std::vector<ResponseRow> flaggedTrials();
    std::vector<TrialRecord> trials(std::int64_t participantId);
    std::int64_t responseCount();

private:
    std::unique_ptr<StudyConnection> connection_;
    std::unique_ptr<ActiveDesignState> active_;
    std::unique_ptr<ParticipantRegistry> participants_;
    std::unique_ptr<ResponseQueue> responses_;
    std::unique_ptr<StudyReadModels> reads_;
};

} // namespace skinlab::experiments
