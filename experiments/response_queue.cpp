#include "experiments/response_queue.h"

#include "common/time.h"
#include "experiments/active_design_state.h"
#include "experiments/study_connection.h"
#include "experiments/study_errors.h"
#include "experiments/study_rows.h"
#include "experiments/study_text.h"

namespace skinlab::experiments {

ResponseOutcome ResponseQueue::storeOne(const ResponseInput& in) {
    SqliteDatabase& db = *connection_.db;
    std::int64_t participantId = 0;
    {
        SqliteStatement s = db.prepare("SELECT id FROM participants WHERE token = ?");
        s.bind(1, in.token);
        if (!s.step()) throw NotFound("unknown participant");
        participantId = s.integer(0);
    }
    // The reference must carry this participant's tag: another participant's trial (or a guessed number) is
    // indistinguishable from one that does not exist.
    TrialRecord trial;
    {
        const std::int64_t id = in.trialId & 0xFFFFFFFFll;
        const std::string unknown = "trial " + std::to_string(in.trialId) + ": unknown trial";
        if (in.trialId <= 0 || trialReference(in.token, id) != in.trialId) throw NotFound(unknown);
        SqliteStatement s = db.prepare(std::string("SELECT ") + kTrialColumns + " FROM trials WHERE id = ?");
        s.bind(1, id);
        if (!s.step()) throw NotFound(unknown);
        trial = readTrial(s);
        if (trial.participantId != participantId) throw NotFound(unknown);
    }
    {
        SqliteStatement s = db.prepare("SELECT participant_id FROM sessions WHERE id = ?");
        s.bind(1, in.sessionId);
        if (!s.step() || s.integer(0) != participantId)
            throw NotFound("session " + std::to_string(in.sessionId) + ": unknown session");
    }
    const bool leftIsA = trial.plan.aOnLeft;
    const std::string chosen = (in.side == "left") == leftIsA ? "A" : "B";
    {
        SqliteStatement s = db.prepare("SELECT chosen FROM responses WHERE trial_id = ?");
        s.bind(1, trial.id);
        if (s.step()) {
            // A re-send (lost acknowledgement, retry after a restart) is harmless; a different answer is not
            // allowed to replace the stored one.
            if (s.text(0) == chosen) return ResponseOutcome::duplicate;
            throw Conflict("trial " + std::to_string(in.trialId) + ": already answered differently");
        }
    }
    {
        SqliteStatement s = db.prepare("SELECT MIN(position) FROM trials WHERE participant_id = ?1 AND id NOT IN"
                                       " (SELECT trial_id FROM responses WHERE participant_id = ?1)");
        s.bind(1, participantId);
        s.step();
        if (s.isNull(0) || s.integer(0) != trial.position)
            throw Conflict("trial " + std::to_string(in.trialId) + ": out of order (the next trial is at position " +
                           (s.isNull(0) ? std::string("none") : std::to_string(s.integer(0))) + ")");
    }
    SqliteStatement insert = db.prepare(
        "INSERT INTO responses (trial_id, participant_id, session_id, chosen, side, response_ms, client_time, "
        "server_time,"
        " viewport_width, viewport_height, device_pixel_ratio, user_agent) VALUES (?,?,?,?,?,?,?,?,?,?,?,?)");
    insert.bind(1, trial.id).bind(2, participantId).bind(3, in.sessionId).bind(4, chosen).bind(5, in.side);
    insert.bind(6, in.responseMs)
        .bind(7, validUtf8(in.clientTime, kMaxStoredText))
        .bind(8, utcTimestamp())
        .bind(9, in.viewportWidth);
    insert.bind(10, in.viewportHeight).bind(11, in.devicePixelRatio).bind(12, validUtf8(in.userAgent, kMaxStoredText));
    insert.run();
    if (in.conditions) {
        SqliteStatement c =
            db.prepare("INSERT INTO trial_conditions (trial_id, page_hidden, focus_lost, fullscreen) VALUES (?,?,?,?)");
        c.bind(1, trial.id).bind(2, in.conditions->pageHidden ? 1 : 0).bind(3, in.conditions->focusLost ? 1 : 0);
        c.bind(4, in.conditions->fullscreen ? 1 : 0);
        c.run();
    }
    active_.noteAnswer(trial, chosen == "A");
    return ResponseOutcome::stored;
}

ResponseOutcome ResponseQueue::record(const ResponseInput& in) {
    if (in.side != "left" && in.side != "right") throw InvalidValue("side: expected \"left\" or \"right\"");
    PendingResponse mine;
    mine.input = &in;
    std::unique_lock queueLock(queueMutex_);
    queue_.push_back(&mine);
    while (!mine.done) {
        if (committing_) {
            queueChanged_.wait(queueLock);
            continue;
        }
        // This thread commits everything queued so far (its own response included).
        committing_ = true;
        std::vector<PendingResponse*> batch;
        batch.swap(queue_);
        queueLock.unlock();
        commitBatch(batch);
        queueLock.lock();
        committing_ = false;
        for (PendingResponse* p : batch) p->done = true;
        queueChanged_.notify_all();
    }
    if (mine.error) std::rethrow_exception(mine.error);
    return mine.outcome;
}

void ResponseQueue::commitBatch(const std::vector<PendingResponse*>& batch) {
    std::lock_guard lock(connection_.mutex);
    try {
        SqliteTransaction tx(*connection_.db);
        for (PendingResponse* p : batch) {
            // Validation only reads, and the insert is the last step, so a rejected response leaves nothing behind.
            try {
                p->outcome = storeOne(*p->input);
            } catch (const StudyRefusal&) {
                p->error = std::current_exception();
            }
        }
        tx.commit();
        active_.commitNotedAnswers();
    } catch (...) {
        active_.dropNotedAnswers();
        // Nothing of this batch was committed: every response not already rejected fails (and is re-sent).
        for (PendingResponse* p : batch)
            if (!p->error) p->error = std::current_exception();
    }
}

} // namespace skinlab::experiments
