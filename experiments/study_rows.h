#pragma once
// Rows of the study file's tables as records (experiments/study_records.h): the column lists the store's queries
// select, the readers of those columns, and the insert of planned trials. Shared by the parts of the store.
#include "experiments/sqlite_database.h"
#include "experiments/study_records.h"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace skinlab::experiments {

// The two judgements of an answer, defined once, in SQL over `responses r`, `trials t` and (LEFT JOIN)
// `trial_conditions c`: the view responses_long, the store's response rows and its catch counts all read them.
// correct: 1 when a catch trial's answer is the expected one, 0 when it is not; NULL for other trials.
inline constexpr const char* kCorrectSql =
    "CASE WHEN t.kind = 'catch' THEN (CASE WHEN r.chosen = t.expected THEN 1 ELSE 0 END) ELSE NULL END";
// flagged: 1 when the page was hidden or lost the focus while the trial was shown, 0 when not; NULL = not recorded.
inline constexpr const char* kFlaggedSql =
    "CASE WHEN c.trial_id IS NULL THEN NULL WHEN c.page_hidden OR c.focus_lost THEN 1 ELSE 0 END";

// Table trials: these columns, in this order, are what readTrial() reads.
inline constexpr const char* kTrialColumns =
    "id, participant_id, position, kind, block, condition_a, condition_b, stimulus_a, stimulus_b, a_on_left,"
    " reference_stimulus, expected";
TrialRecord readTrial(const SqliteStatement& s);

// Table participants: these columns, in this order, are what readParticipant() reads.
inline constexpr const char* kParticipantColumns =
    "id, participant_index, label, token, seed, completion_code, created_at";
ParticipantRecord readParticipant(const SqliteStatement& s);

// Table viewing_conditions as `v` (LEFT JOINed to a session): readViewing() reads these columns starting at
// `first`; a NULL first column (no row: not reported) gives nullopt.
inline constexpr const char* kViewingColumns =
    "v.screen_width, v.screen_height, v.screen_width_px, v.screen_height_px, v.colour_depth, v.fullscreen,"
    " v.pointer_fine, v.touch_points, v.mobile, v.pixels_per_mm, v.viewing_distance_mm, v.pixels_per_degree";
std::optional<ViewingConditions> readViewing(const SqliteStatement& s, int first, double devicePixelRatio,
                                             int viewportWidth, int viewportHeight);

// Every response joined with its trial, participant, stimuli, session, trial conditions, platform ids and the
// session's viewing conditions, ordered by participant and position (the exports' and the store's read);
// readResponseRow() reads one row of it.
std::string responseRowsQuery();
ResponseRow readResponseRow(const SqliteStatement& s);

// Every session with its participant and viewing conditions, in order of starting; readSessionViewing() reads one.
std::string sessionViewingsQuery();
SessionViewing readSessionViewing(const SqliteStatement& s);

// Every participant with its counts (trials, answers, test/repeat answers, catch answers and correct ones, last
// answer) and platform ids, in joining order; readParticipantStatus() reads one row. `plannedTotal` > 0: the length
// of an active design's participation (its trials are stored batch by batch), else the stored trials are counted.
std::string participantStatusQuery();
ParticipantStatus readParticipantStatus(const SqliteStatement& s, int plannedTotal);

// Inserts a participant's planned trials at positions firstPosition, firstPosition + 1, ... (inside the caller's
// transaction).
void insertTrials(SqliteDatabase& db, std::int64_t participantId, const std::vector<PlannedTrial>& plan,
                  int firstPosition = 0);

} // namespace skinlab::experiments
