#pragma once
// The records the study file reads and writes: participants, sessions, trials, responses and what the exports and
// the researcher's overview read back. Plain values; the tables behind them: docs/experiments.md ("The study file").
#include "experiments/recruitment.h"
#include "experiments/trial_plan.h"
#include "experiments/viewing_conditions.h"

#include <cstdint>
#include <optional>
#include <string>

namespace skinlab::experiments {

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

// How a study file is opened: to serve it (readWrite; refused at start when it cannot be written), or only to read it
// (readOnly: `study status`, `export`, `backup`, `plan`, `simulate`; also on a read-only mount, common/sqlite_read.h).
enum class StudyAccess { readWrite, readOnly };

// At most this many sessions per participant (each page load starts one); more are refused (LimitReached).
inline constexpr int kDefaultSessionsPerParticipant = 32;
// At most this many resumes per participant (beyond: LimitReached), and apart from them at most this many refused
// attempts (joins with its platform id, without its secret) recorded per participant (beyond: refused without a
// row). Refused attempts never count against the participant's resumes: others cannot use them up. (Session rows
// are bounded by the sessions' limit.)
inline constexpr int kMaxVisitsPerParticipant = 100;

// What the page saw while one trial was shown (sent with the response).
struct TrialConditions {
    bool pageHidden = false; // document hidden at any moment (another tab, minimised window)
    bool focusLost = false;  // the window lost the focus at any moment
    bool fullscreen = false; // full screen when answered
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
    std::optional<bool> correct; // catch trials only (kCorrectSql, experiments/study_rows.h)
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
    std::optional<bool> flagged;               // hidden or unfocused while shown (kFlaggedSql); absent = not recorded
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

} // namespace skinlab::experiments
