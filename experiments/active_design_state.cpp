#include "experiments/active_design_state.h"

#include "experiments/active_plan.h"
#include "experiments/study_connection.h"
#include "experiments/study_rows.h"

#include <algorithm>
#include <string>

namespace skinlab::experiments {

ActiveDesignState::ActiveDesignState(StudyConnection& connection) : connection_(connection) {
    for (std::size_t b = 0; b < connection_.definition.blocks.size(); ++b)
        posteriorCache_.push_back(std::make_unique<BlockPosteriorCache>());
}

ActiveDesignState::~ActiveDesignState() = default;

void ActiveDesignState::loadCounts() {
    if (countsLoaded_) return;
    answers_.assign(connection_.definition.blocks.size(), {});
    for (std::size_t b = 0; b < connection_.definition.blocks.size(); ++b) {
        const StudyBlock& block = connection_.definition.blocks[b];
        std::map<std::string, int> index;
        for (std::size_t i = 0; i < block.conditions.size(); ++i) index[block.conditions[i]] = static_cast<int>(i);
        // Every stored answer to a test trial of the block, of every participant, counted per ordered pair.
        SqliteStatement s = connection_.db->prepare(
            "SELECT t.condition_a, t.condition_b, SUM(r.chosen = 'A'), SUM(r.chosen = 'B') FROM responses r"
            " JOIN trials t ON t.id = r.trial_id WHERE t.block = ? AND t.kind IN ('test','repeat')"
            " GROUP BY t.condition_a, t.condition_b");
        s.bind(1, block.name);
        BlockAnswers& answers = answers_[b];
        while (s.step()) {
            const auto a = index.find(s.text(0)), c = index.find(s.text(1));
            if (a == index.end() || c == index.end() || a->second == c->second) continue;
            const double aWon = static_cast<double>(s.integer(2)), cWon = static_cast<double>(s.integer(3));
            auto& entry = answers.counts[{std::min(a->second, c->second), std::max(a->second, c->second)}];
            entry.first += a->second < c->second ? aWon : cWon;
            entry.second += a->second < c->second ? cWon : aWon;
            answers.generation += static_cast<std::uint64_t>(aWon + cWon);
        }
    }
    countsLoaded_ = true;
}

active::ScorePosterior ActiveDesignState::blockPosterior(std::size_t b, std::uint64_t generation) {
    BlockPosteriorCache& cache = *posteriorCache_[b];
    std::lock_guard fitting(cache.mutex);
    if (cache.valid && cache.generation >= generation) return cache.posterior;
    // The latest answers (at least `generation` of them; more when some arrived while this request waited).
    std::vector<active::PairCount> counts;
    std::uint64_t latest = 0;
    {
        std::lock_guard lock(connection_.mutex);
        loadCounts();
        const BlockAnswers& answers = answers_[b];
        latest = answers.generation;
        for (const auto& [pair, won] : answers.counts)
            counts.push_back({pair.first, pair.second, won.first, won.second});
    }
    cache.posterior =
        active::fitPosteriorFromCounts(static_cast<int>(connection_.definition.blocks[b].conditions.size()), counts,
                                       plannerPosteriorOptions(connection_.definition.design));
    cache.generation = latest;
    cache.valid = true;
    return cache.posterior;
}

ActiveDesignState::Extension ActiveDesignState::extendPlan(std::int64_t participantId) {
    std::int64_t index = 0;
    std::uint64_t seed = 0;
    std::vector<PlannedTrial> stored;
    std::vector<std::uint64_t> generations;
    {
        std::lock_guard lock(connection_.mutex);
        SqliteStatement s = connection_.db->prepare("SELECT participant_index, seed FROM participants WHERE id = ?");
        s.bind(1, participantId);
        if (!s.step()) return Extension::complete;
        index = s.integer(0);
        seed = static_cast<std::uint64_t>(s.integer(1));
        SqliteStatement t = connection_.db->prepare(std::string("SELECT ") + kTrialColumns +
                                                    " FROM trials WHERE participant_id = ? ORDER BY position");
        t.bind(1, participantId);
        while (t.step()) stored.push_back(readTrial(t).plan);
        loadCounts();
        for (const BlockAnswers& answers : answers_) generations.push_back(answers.generation);
    }
    // Planned without the store's lock: other requests go on meanwhile.
    const std::vector<PlannedTrial> next = nextActiveTrials(
        connection_.definition, index, seed, stored, [&](std::size_t b) { return blockPosterior(b, generations[b]); });
    if (next.empty()) return Extension::complete;
    std::lock_guard lock(connection_.mutex);
    SqliteTransaction tx(*connection_.db);
    {
        // Re-check: nothing stored for this participant since the read above (a concurrent request planned).
        SqliteStatement s = connection_.db->prepare("SELECT COUNT(*) FROM trials WHERE participant_id = ?");
        s.bind(1, participantId);
        s.step();
        if (s.integer(0) != static_cast<std::int64_t>(stored.size())) return Extension::raced;
    }
    insertTrials(*connection_.db, participantId, next, static_cast<int>(stored.size()));
    tx.commit();
    return Extension::stored;
}

void ActiveDesignState::noteAnswer(const TrialRecord& trial, bool aChosen) {
    const StudyDefinition& definition = connection_.definition;
    if (definition.design.activePairs && (trial.plan.kind == TrialKind::test || trial.plan.kind == TrialKind::repeat))
        for (std::size_t b = 0; b < definition.blocks.size(); ++b) {
            const StudyBlock& block = definition.blocks[b];
            if (block.name != trial.plan.block) continue;
            const auto a = std::find(block.conditions.begin(), block.conditions.end(), trial.plan.conditionA);
            const auto c = std::find(block.conditions.begin(), block.conditions.end(), trial.plan.conditionB);
            if (a == block.conditions.end() || c == block.conditions.end() || a == c) break;
            const int ia = static_cast<int>(a - block.conditions.begin()),
                      ic = static_cast<int>(c - block.conditions.begin());
            notedAnswers_.push_back({b, std::min(ia, ic), std::max(ia, ic), aChosen == (ia < ic)});
            break;
        }
}

void ActiveDesignState::commitNotedAnswers() {
    // The committed answers of an active design's test trials join their blocks' counts.
    if (countsLoaded_)
        for (const ActiveAnswer& a : notedAnswers_) {
            BlockAnswers& answers = answers_[a.block];
            auto& entry = answers.counts[{a.i, a.j}];
            (a.iWon ? entry.first : entry.second) += 1.0;
            ++answers.generation;
        }
    notedAnswers_.clear();
}

void ActiveDesignState::dropNotedAnswers() { notedAnswers_.clear(); }

} // namespace skinlab::experiments
