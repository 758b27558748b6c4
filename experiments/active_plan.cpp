#include "experiments/active_plan.h"

#include "common/error.h"
#include "common/seeded_random.h"

#include <algorithm>
#include <limits>
#include <map>

namespace skinlab::experiments {

std::vector<PlannedTrial> nextActiveTrials(const StudyDefinition& study, std::int64_t participantIndex,
                                           std::uint64_t seed, const std::vector<PlannedTrial>& stored,
                                           const std::function<active::ScorePosterior(std::size_t)>& posteriorOf) {
    if (!study.design.activePairs) throw RuntimeError("nextActiveTrials: not an active design");
    const std::vector<PlannedTrial> skeleton = planTrials(study, participantIndex, seed);
    std::size_t position = stored.size();
    std::vector<PlannedTrial> out;
    if (position >= skeleton.size()) return out;
    while (position < skeleton.size() && !isActiveSlot(skeleton[position])) out.push_back(skeleton[position++]);
    if (position == skeleton.size()) return out;

    // The block: fewest test trials so far relative to its batch size, ties in rotating order.
    const std::size_t blockCount = study.blocks.size();
    std::map<std::string, int> testsIn;
    int testsSoFar = 0;
    const PlannedTrial* lastTest = nullptr;
    for (const PlannedTrial& t : stored)
        if (t.kind == TrialKind::test) {
            ++testsIn[t.block];
            ++testsSoFar;
            lastTest = &t;
        }
    std::size_t chosen = blockCount;
    double chosenLoad = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < blockCount; ++k) {
        const std::size_t b = (static_cast<std::size_t>(participantIndex) + k) % blockCount;
        const StudyBlock& block = study.blocks[b];
        const double load = static_cast<double>(testsIn[block.name]) / static_cast<double>(block.conditions.size() - 1);
        if (load < chosenLoad) {
            chosenLoad = load;
            chosen = b;
        }
    }
    const StudyBlock& block = study.blocks[chosen];
    const active::ScorePosterior posterior = posteriorOf(chosen);
    if (posterior.conditions() != static_cast<int>(block.conditions.size()))
        throw RuntimeError("active plan: posterior of block \"" + block.name + "\" has the wrong size");
    const std::uint64_t batchSeed = combineSeed(seed, static_cast<std::uint64_t>(position));
    std::vector<std::pair<int, int>> batch = active::spanningTreeBatch(posterior, batchSeed);
    // active_batch: the most valuable pairs of the tree only (they come first); the rest is re-planned later.
    const auto batchSize = static_cast<std::size_t>(study.design.activeBatch);
    if (batchSize > 0 && batch.size() > batchSize) batch.resize(batchSize);
    // Never the pair just shown first.
    if (lastTest && lastTest->block == block.name && batch.size() > 1) {
        const auto& [i, j] = batch.front();
        const std::string& a = block.conditions[static_cast<std::size_t>(i)];
        const std::string& b = block.conditions[static_cast<std::size_t>(j)];
        if ((lastTest->conditionA == a && lastTest->conditionB == b) ||
            (lastTest->conditionA == b && lastTest->conditionB == a))
            std::rotate(batch.begin(), batch.begin() + 1, batch.end());
    }

    SeededRandom random(combineSeed(batchSeed, 0x5ee5u));
    std::size_t next = 0;
    while (position < skeleton.size()) {
        if (isActiveSlot(skeleton[position])) {
            if (next == batch.size()) break;
            auto [i, j] = batch[next++];
            if (random.coin()) std::swap(i, j);
            PlannedTrial t;
            t.kind = TrialKind::test;
            t.block = block.name;
            t.conditionA = block.conditions[static_cast<std::size_t>(i)];
            t.conditionB = block.conditions[static_cast<std::size_t>(j)];
            t.stimulusA = block.conditionStimulus[static_cast<std::size_t>(i)];
            t.stimulusB = block.conditionStimulus[static_cast<std::size_t>(j)];
            t.aOnLeft = ((testsSoFar + participantIndex) % 2) == 0;
            t.referenceStimulus = study.design.showReference ? block.referenceStimulus : -1;
            ++testsSoFar;
            out.push_back(std::move(t));
        } else {
            out.push_back(skeleton[position]);
        }
        ++position;
    }
    return out;
}

active::PosteriorOptions plannerPosteriorOptions(const StudyDesign& design) {
    active::PosteriorOptions options;
    options.priorVariance = design.activePriorSd * design.activePriorSd;
    return options;
}

std::vector<active::Comparison> blockComparisons(const StudyBlock& block, const std::vector<PlannedTrial>& trials,
                                                 const std::vector<bool>& aSelected) {
    std::map<std::string, int> index;
    for (std::size_t i = 0; i < block.conditions.size(); ++i) index[block.conditions[i]] = static_cast<int>(i);
    std::vector<active::Comparison> out;
    for (std::size_t k = 0; k < trials.size(); ++k) {
        const PlannedTrial& t = trials[k];
        if (t.block != block.name || (t.kind != TrialKind::test && t.kind != TrialKind::repeat)) continue;
        const auto a = index.find(t.conditionA), b = index.find(t.conditionB);
        if (a == index.end() || b == index.end()) continue;
        out.push_back(aSelected[k] ? active::Comparison{a->second, b->second}
                                   : active::Comparison{b->second, a->second});
    }
    return out;
}

} // namespace skinlab::experiments
