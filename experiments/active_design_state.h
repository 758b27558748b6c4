#pragma once
// An active design's state in a running store (experiments/active_plan.h plans the batches): the answer counts of
// every block, kept in memory (read from study.db on first use, updated after each committed response), one
// posterior cache per block, and the extension of a participant's plan by its next batch.
//
// Planning a batch runs outside the connection's mutex: what it needs (the participant's stored trials, the
// generation of each block's answers) is read under the lock, the batch is planned without it, and the lock is
// taken again to re-check that nothing was stored for the participant meanwhile before the batch is stored (one
// transaction).
#include "analysis/scaling/active_sampling.h"
#include "experiments/study_records.h"

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

namespace skinlab::experiments {

// Active sampling (the posterior, the batches) is the analysis library's.
namespace active = analysis::scaling::active;

struct StudyConnection;

class ActiveDesignState {
public:
    explicit ActiveDesignState(StudyConnection& connection);
    ~ActiveDesignState();

    enum class Extension { stored, complete, raced };
    // Plans the participant's next stretch from the current answers and stores it. `complete`: the plan holds
    // every trial already (or the participant is unknown); `raced`: another request stored trials for the
    // participant meanwhile, nothing was stored. Takes the connection's mutex itself (not held by the caller).
    Extension extendPlan(std::int64_t participantId);

    // The connection's mutex held, inside the transaction that stores a response: notes the answer to `trial`
    // (A chosen or not) when it counts for an active design (a test or repeat trial of a known pair).
    void noteAnswer(const TrialRecord& trial, bool aChosen);
    // The connection's mutex held: after the COMMIT, the noted answers join their blocks' counts (when loaded);
    // after a failed transaction they are dropped.
    void commitNotedAnswers();
    void dropNotedAnswers();

private:
    // The connection's mutex held: the in-memory answer counts of every block, read from the database on first use.
    void loadCounts();
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

    StudyConnection& connection_;
    bool countsLoaded_ = false;
    std::vector<BlockAnswers> answers_;                                // per block, under the connection's mutex
    std::vector<ActiveAnswer> notedAnswers_;                           // stored in the open transaction, same mutex
    std::vector<std::unique_ptr<BlockPosteriorCache>> posteriorCache_; // per block, fixed size
};

} // namespace skinlab::experiments
