#pragma once
// study.db: one SQLite file (WAL journal, synchronous=FULL) holding the design, the stimulus manifest and its
// hash, participants, sessions, planned trials and responses. Schema: docs/experiments.md ("The study file").
//
// Crash safety: each response is validated and inserted inside an IMMEDIATE transaction (responses arriving
// together share one: group commit), and recordResponse() returns only after COMMIT, which with WAL + synchronous=FULL means the WAL frame is fsynced. The server
// acknowledges after that, so an acknowledged response survives kill -9 and power loss. A response is keyed by
// its trial (PRIMARY KEY), so a re-sent response can never be stored twice.
#include "experiments/recruitment.h"
#include "experiments/active_sampling.h"
#include "experiments/study_definition.h"
#include "experiments/trial_plan.h"
#include "experiments/viewing_conditions.h"

#include <cstdint>
#include <filesystem>
#include <map>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace skinlab::experiments {

class SqliteDatabase;

struct ParticipantRecord {
    std::int64_t id = 0;
    std::int64_t index = 0; // 0-based order of joining (drives the side mirroring of trial_plan.h)
    std::string label;      // the observer name in exports
    std::string token;      // secret in the participant link
    std::uint64_t seed = 0;
    std::string completionCode;
    std::string createdAt;
    bool resumed = false; // join(): an existing participant was returned (same join key, or platform id with its
                          // join key or the platform's session id)
};

// Where a request came from: the client's address and whether the TCP peer ("peer") or a trusted proxy
// ("forwarded") said so.
struct ClientOrigin {
    std::string address;
    std::string source = "peer";
};

// At most this many sessions per participant (each page load starts one); more are refused with 429.
inline constexpr int kDefaultSessionsPerParticipant = 32;
// At most this many resumes and refused attempts (joins) are recorded per participant; beyond, a resume is refused
// with 429 and a refused attempt is refused without a row. (Session rows are bounded by the sessions' limit.)
inline constexpr int kMaxVisitsPerParticipant = 100;

// What the page saw while one trial was shown (sent with the response).
struct TrialConditions {
    bool pageHidden = false; // document hidden at any moment (another tab, minimised window)
    bool focusLost = false;  // the window lost the focus at any moment
    bool fullscreen = false; // full screen when answered
    bool flagged() const { return pageHidden || focusLost; }
};

struct TrialRecord {
    std::int64_t id = 0; // global trial id
    std::int64_t participantId = 0;
    int position = 0; // 0-based order within the participant's plan
    PlannedTrial plan;
};

struct ResponseInput {
    std::string token;        // participant token
    std::int64_t trialId = 0; // the trial's reference (trialReference()), as the participant API shows it
    std::string side;         // "left" | "right"
    std::int64_t sessionId = 0;
    double responseMs = 0;  // from stimulus onset to key/click, measured by the page
    std::string clientTime; // client's ISO-8601 clock at the response
    int viewportWidth = 0;  // CSS pixels
    int viewportHeight = 0;
    double devicePixelRatio = 1;
    std::string userAgent;
    std::optional<TrialConditions> conditions; // absent: the client reported none
};

enum class ResponseOutcome { stored, duplicate };

struct Progress {
    int answered = 0;
    int total = 0;
    bool completed() const { return answered >= total; }
};

struct ParticipantStatus {
    ParticipantRecord participant;
    Progress progress;
    int testAnswered = 0; // test + repeat
    int catchAnswered = 0;
    int catchCorrect = 0;
    std::string lastResponseAt;
    std::optional<ExternalIds> external; // the recruitment platform's ids, when the participant came from one
};

// One stored response joined with its trial: everything the exports need.
struct ResponseRow {
    std::string observer;
    std::int64_t participantId = 0;
    std::int64_t trialId = 0;
    int position = 0;
    TrialKind kind = TrialKind::test;
    std::string scene; // block name
    std::string conditionA;
    std::string conditionB;
    std::string stimulusA; // manifest ids ("blank" for the panel)
    std::string stimulusB;
    bool aOnLeft = true;
    bool aSelected = true;
    std::optional<bool> correct; // catch trials only
    double responseMs = 0;
    std::string clientTime;
    std::string serverTime;
    int viewportWidth = 0;
    int viewportHeight = 0;
    double devicePixelRatio = 1;
    std::string userAgent;
    std::int64_t sessionId = 0;
    std::optional<TrialConditions> conditions; // per trial; absent = not recorded
    double sessionDevicePixelRatio = 1;        // at the session's start (a change = browser zoom)
    std::optional<ViewingConditions> viewing;  // the session's; absent = not reported
    std::optional<ExternalIds> external;       // the participant's platform ids
    bool flagged() const { return conditions && conditions->flagged(); }
};

// The viewing conditions of one session, with whose it is.
struct SessionViewing {
    std::string observer;
    std::int64_t participantId = 0;
    std::int64_t sessionId = 0;
    std::string startedAt;
    std::string userAgent;
    int viewportWidth = 0;
    int viewportHeight = 0;
    double devicePixelRatio = 1;
    std::optional<ViewingConditions> viewing; // absent: the client reported only the viewport
};

class StudyStore {
public:
    // Writes a new study file atomically (built under a temporary name, then renamed). Refuses to overwrite an
    // existing file: a study holds responses that must never be lost by a repeated `create`.
    static void create(const std::filesystem::path& path, const StudyDefinition& definition,
                       const std::string& designText, const StimulusManifest& manifest);

    explicit StudyStore(const std::filesystem::path& path);
    ~StudyStore();

    const StudyDefinition& definition() const { return definition_; }
    const std::filesystem::path& path() const { return path_; }
    std::string meta(const std::string& key) const;
    // Labels of the participants `study simulate` sent (their join keys say so), in joining order.
    std::vector<std::string> simulatedLabels() const;

    // A new participant with a fresh token, seed and planned trials (one transaction). `label` empty = "P001"...
    // `joinKey` (a secret chosen by the client, may be empty) makes joining idempotent: a retried join whose first
    // answer was lost returns the participant it created. Throws RequestError 409 when the label is taken.
    // `external` (a recruitment platform's ids, normalised): one platform id is one participant. A join with a known
    // platform id resumes that participant only with something only that participant's browser holds: the join key
    // of its first join, or the platform's per-attempt session id (Prolific SESSION_ID, MTurk assignmentId) it first
    // joined with; the platform id alone never does. Otherwise RequestError 409, and the refused attempt is recorded.
    // `origin`: stored with a new participant (participant_addresses) and with every resume or refused attempt
    // (participant_visits).
    ParticipantRecord join(const std::string& label, const std::string& joinKey = "",
                           const std::optional<ExternalIds>& external = std::nullopt,
                           const std::optional<ClientOrigin>& origin = std::nullopt);
    // Throws RequestError 404 for an unknown token.
    ParticipantRecord participant(const std::string& token);
    // `viewing` (when the page reported it) is stored with the session. A participant who already has
    // `maxSessions` sessions (0 = no limit) is refused with RequestError 429 and nothing is stored. `origin`: recorded
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
    // Validates and commits one response (see the header comment). Rejections throw RequestError:
    // 404 unknown participant, trial or session (another participant's trial or session is unknown too: no answer
    // tells whose it is), 409 out of order or a
    // different answer to an already answered trial.
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
    // Group commit: concurrent responses are queued; one waiting thread at a time commits everything queued in one
    // transaction (one fsync), then wakes the others. Each response is still validated on its own, in arrival
    // order, inside that transaction, and none is acknowledged before the COMMIT.
    struct PendingResponse {
        const ResponseInput* input = nullptr;
        ResponseOutcome outcome = ResponseOutcome::stored;
        std::exception_ptr error;
        bool done = false;
    };
    void commitBatch(const std::vector<PendingResponse*>& batch);
    ResponseOutcome storeOne(const ResponseInput& input); // inside an open transaction, mutex_ held
    // Active designs (experiments/active_plan.h). Planning a batch runs outside mutex_: what it needs (the
    // participant's stored trials, the generation of each block's answers) is read under the lock, the batch is
    // planned without it, and the lock is taken again to re-check that nothing was stored for the participant
    // meanwhile before the batch is stored (one transaction).
    enum class ActiveExtension { stored, complete, raced };
    ActiveExtension extendActivePlan(std::int64_t participantId);
    ParticipantRecord joinLocked(const std::string& label, const std::string& joinKey,
                                 const std::optional<ExternalIds>& external, const std::optional<ClientOrigin>& origin,
                                 bool& created);
    // mutex_ held, inside a transaction.
    void insertVisit(std::int64_t participantId, const char* outcome, const ClientOrigin& origin);
    int visitCount(std::int64_t participantId);
    std::optional<TrialRecord> firstUnanswered(std::int64_t participantId); // mutex_ held
    int plannedTrialCount() const;                                          // per participant
    // mutex_ held: the in-memory answer counts of every block, read from the database on first use and updated
    // after each committed response.
    void loadActiveCounts();
    // The posterior of block b from answers at least as recent as `generation` (a block's generation counts its
    // committed answers). One fit per block at a time; a request waiting for a running fit takes its result when
    // that covers the request's generation, so answers arriving together cost one fit, not one each.
    active::ScorePosterior blockPosterior(std::size_t block, std::uint64_t generation);
    struct ActiveAnswer {
        std::size_t block = 0;
        int i = 0, j = 0; // condition indices, i < j
        bool iWon = false;
    };
    struct BlockAnswers {
        std::map<std::pair<int, int>, std::pair<double, double>> counts; // (i < j) → (i won, j won)
        std::uint64_t generation = 0;
    };
    struct BlockPosteriorCache {
        std::mutex mutex; // held while fitting
        bool valid = false;
        std::uint64_t generation = 0;
        active::ScorePosterior posterior;
    };
    bool activeCountsLoaded_ = false;
    std::vector<BlockAnswers> activeAnswers_;                          // per block, under mutex_
    std::vector<ActiveAnswer> uncommittedAnswers_;                     // stored in the open transaction, under mutex_
    std::vector<std::unique_ptr<BlockPosteriorCache>> posteriorCache_; // per block, fixed size

    std::unique_ptr<SqliteDatabase> db_;
    std::filesystem::path path_;
    StudyDefinition definition_;
    std::mutex mutex_; // one connection shared by the server's threads; SQLite serialises writers anyway
    std::mutex queueMutex_;
    std::condition_variable queueChanged_;
    std::vector<PendingResponse*> queue_;
    bool committing_ = false;
};

// The participant-facing reference of a trial: the row id with a tag derived from the participant's token above
// it, so a trial reference can be neither guessed nor used by another participant (both answer 404).
std::int64_t trialReference(const std::string& participantToken, std::int64_t trialId);
// `text` as well-formed UTF-8 of at most `maxBytes` bytes: ill-formed sequences and control characters become
// U+FFFD, and a character cut by the limit is dropped whole. Every client string is stored through this.
std::string validUtf8(std::string_view text, std::size_t maxBytes);

// Random lower-case hex string of `bytes` bytes from the OS entropy source (tokens).
std::string randomHex(std::size_t bytes);

} // namespace skinlab::experiments
