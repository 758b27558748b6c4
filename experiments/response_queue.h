#pragma once
// Storing responses: each response is validated and inserted inside an IMMEDIATE transaction, and record() returns
// only after COMMIT (WAL + synchronous=FULL: the WAL frame is fsynced), so an acknowledged response survives kill -9
// and power loss. A response is keyed by its trial (PRIMARY KEY), so a re-sent response is never stored twice.
//
// Group commit: concurrent responses are queued; one waiting thread at a time commits everything queued in one
// transaction (one fsync), then wakes the others. Each response is still validated on its own, in arrival order,
// inside that transaction, and none is acknowledged before the COMMIT.
#include "experiments/study_records.h"

#include <condition_variable>
#include <exception>
#include <mutex>
#include <vector>

namespace skinlab::experiments {

struct StudyConnection;
class ActiveDesignState;

class ResponseQueue {
public:
    // `active`: told of every stored answer (its counts follow the committed responses).
    ResponseQueue(StudyConnection& connection, ActiveDesignState& active) : connection_(connection), active_(active) {}

    // Validates and commits one response. Refusals (nothing stored): InvalidValue (side), NotFound (participant,
    // trial or session; another participant's trial or session is unknown too: no answer tells whose it is),
    // Conflict (out of order, or a different answer to an already answered trial). Any other failure of the
    // transaction fails every response of its batch (none was committed; each is re-sent).
    ResponseOutcome record(const ResponseInput& input);

private:
    struct PendingResponse {
        const ResponseInput* input = nullptr;
        ResponseOutcome outcome = ResponseOutcome::stored;
        std::exception_ptr error;
        bool done = false;
    };
    void commitBatch(const std::vector<PendingResponse*>& batch);
    ResponseOutcome storeOne(const ResponseInput& input); // inside an open transaction, the connection's mutex held

    StudyConnection& connection_;
    ActiveDesignState& active_;
    std::mutex queueMutex_;
    std::condition_variable queueChanged_;
    std::vector<PendingResponse*> queue_;
    bool committing_ = false;
};

} // namespace skinlab::experiments
