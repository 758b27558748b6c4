#include "experiments/trial_plan.h"

#include "common/error.h"
#include "common/seeded_random.h"

#include <algorithm>

namespace skinlab::experiments {

TrialKind trialKindFromName(const std::string& name) {
    if (name == "practice") return TrialKind::practice;
    if (name == "repeat") return TrialKind::repeat;
    if (name == "catch") return TrialKind::catchTrial;
    if (name == "test") return TrialKind::test;
    throw RuntimeError("unknown trial kind \"" + name + "\" in study.db");
}

namespace {

// FNV-1a: a fixed, portable string hash (std::hash is implementation-defined), so a pair's side pattern
// depends only on the design seed and the names.
std::uint64_t stableHash(const std::string& text) {
    std::uint64_t h = 1469598103934665603ull;
    for (unsigned char c : text) {
        h ^= c;
        h *= 1099511628211ull;
    }
    return h;
}

bool samePair(const PlannedTrial& x, const PlannedTrial& y) {
    return x.block == y.block && x.stimulusA == y.stimulusA && x.stimulusB == y.stimulusB;
}

// Reorders trials (keeping the shuffled order as far as possible) so that no pair follows itself: each next trial
// is the first remaining one that differs from the last placed; trials left over at the end (all the same pair)
// are slotted in where neither neighbour is that pair. Bounded: quadratic in the number of trials.
void separateRepeats(std::vector<PlannedTrial>& trials) {
    std::vector<PlannedTrial> remaining = trials;
    std::vector<PlannedTrial> out;
    out.reserve(trials.size());
    while (!remaining.empty()) {
        std::size_t pick = 0;
        while (pick < remaining.size() && !out.empty() && samePair(remaining[pick], out.back())) ++pick;
        if (pick == remaining.size()) break;
        out.push_back(remaining[pick]);
        remaining.erase(remaining.begin() + static_cast<std::ptrdiff_t>(pick));
    }
    for (const PlannedTrial& t : remaining) {
        std::size_t slot = out.size();
        for (std::size_t k = 0; k <= out.size(); ++k) {
            const bool previousDiffers = k == 0 || !samePair(out[k - 1], t);
            const bool nextDiffers = k == out.size() || !samePair(out[k], t);
            if (previousDiffers && nextDiffers) {
                slot = k;
                break;
            }
        }
        out.insert(out.begin() + static_cast<std::ptrdiff_t>(slot), t); // at the end only if no slot exists
    }
    trials = std::move(out);
}

} // namespace

std::uint64_t participantSeed(std::uint64_t designSeed, std::int64_t participantIndex) {
    // Kept within SQLite's signed 64-bit integers.
    return combineSeed(designSeed, static_cast<std::uint64_t>(participantIndex)) >> 1;
}

std::vector<PlannedTrial> planTrials(const StudyDefinition& study, std::int64_t participantIndex, std::uint64_t seed) {
    const StudyDesign& design = study.design;
    SeededRandom random(seed);
    const bool participantFlip = (participantIndex % 2) != 0;

    // Test and repeat trials, grouped by block.
    std::vector<std::vector<PlannedTrial>> perBlock;
    for (const StudyBlock& block : study.blocks) {
        std::vector<PlannedTrial> trials;
        for (const auto& [i, j] : block.pairs) {
            const std::string& a = block.conditions[static_cast<std::size_t>(i)];
            const std::string& b = block.conditions[static_cast<std::size_t>(j)];
            // Side of the first repetition for participant 0: fixed by the design seed and the pair, so that the
            // mirror rule across participants holds for every pair.
            const bool base = (combineSeed(design.seed, stableHash(block.name + '\x1f' + a + '\x1f' + b)) & 1u) != 0;
            for (int rep = 0; rep < design.repetitions; ++rep) {
                PlannedTrial t;
                t.kind = rep == 0 ? TrialKind::test : TrialKind::repeat;
                t.block = block.name;
                t.conditionA = a;
                t.conditionB = b;
                t.stimulusA = block.conditionStimulus[static_cast<std::size_t>(i)];
                t.stimulusB = block.conditionStimulus[static_cast<std::size_t>(j)];
                t.aOnLeft = (base != ((rep % 2) != 0)) != participantFlip;
                t.referenceStimulus = design.showReference ? block.referenceStimulus : -1;
                trials.push_back(t);
            }
        }
        perBlock.push_back(std::move(trials));
    }

    std::vector<PlannedTrial> main;
    if (design.activePairs) {
        main.assign(static_cast<std::size_t>(design.trialsPerParticipant), PlannedTrial{}); // open slots
    } else if (design.blockOrder == "grouped") {
        std::vector<std::size_t> order(perBlock.size());
        for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
        random.shuffle(order);
        for (std::size_t b : order) {
            random.shuffle(perBlock[b]);
            separateRepeats(perBlock[b]);
            main.insert(main.end(), perBlock[b].begin(), perBlock[b].end());
        }
    } else {
        for (auto& trials : perBlock) main.insert(main.end(), trials.begin(), trials.end());
        random.shuffle(main);
        separateRepeats(main);
    }

    // Catch trials: blank panels on randomly chosen test stimuli, then the declared pairs.
    std::vector<PlannedTrial> catches;
    for (int c = 0; c < design.blankCatchTrials; ++c) {
        const StudyBlock& block = study.blocks[random.below(study.blocks.size())];
        const std::size_t k = random.below(block.conditions.size());
        PlannedTrial t;
        t.kind = TrialKind::catchTrial;
        t.block = block.name;
        t.conditionA = block.conditions[k];
        t.conditionB = "blank";
        t.stimulusA = block.conditionStimulus[k];
        t.stimulusB = kBlankStimulus;
        t.referenceStimulus = design.showReference ? block.referenceStimulus : -1;
        t.expected = 'A';
        catches.push_back(t);
    }
    for (const StudyCatchPair& pair : study.catchPairs)
        for (int r = 0; r < pair.repeat; ++r) {
            PlannedTrial t;
            t.kind = TrialKind::catchTrial;
            t.block = pair.block;
            t.stimulusA = pair.first;
            t.stimulusB = pair.second;
            t.conditionA = study.stimuli[static_cast<std::size_t>(pair.first)].condition;
            t.conditionB = study.stimuli[static_cast<std::size_t>(pair.second)].condition;
            t.expected = pair.expectFirst ? 'A' : 'B';
            catches.push_back(t);
        }
    random.shuffle(catches);
    // The correct answer alternates sides, starting on a random side.
    const bool firstCorrectLeft = random.coin();
    for (std::size_t c = 0; c < catches.size(); ++c) {
        const bool correctLeft = firstCorrectLeft != ((c % 2) != 0);
        catches[c].aOnLeft = (catches[c].expected == 'A') == correctLeft;
    }

    // Insert catch c at a random position inside segment c of the test sequence (never before the first test).
    std::vector<PlannedTrial> sequence;
    const std::size_t n = main.size();
    const std::size_t count = catches.size();
    std::vector<std::size_t> insertBefore(count);
    for (std::size_t c = 0; c < count; ++c) {
        const std::size_t lo = std::max<std::size_t>(1, c * n / count);
        const std::size_t hi = std::max(lo, (c + 1) * n / count);
        insertBefore[c] = lo + random.below(hi - lo + 1);
    }
    std::size_t nextCatch = 0;
    for (std::size_t i = 0; i <= n; ++i) {
        while (nextCatch < count && insertBefore[nextCatch] == i) sequence.push_back(catches[nextCatch++]);
        if (i < n) sequence.push_back(main[i]);
    }

    // Practice: random pairs from the study, random sides, first.
    std::vector<PlannedTrial> plan;
    for (int p = 0; p < design.practiceTrials; ++p) {
        const StudyBlock& block = study.blocks[random.below(study.blocks.size())];
        const auto& [i, j] = block.pairs[random.below(block.pairs.size())];
        PlannedTrial t;
        t.kind = TrialKind::practice;
        t.block = block.name;
        t.conditionA = block.conditions[static_cast<std::size_t>(i)];
        t.conditionB = block.conditions[static_cast<std::size_t>(j)];
        t.stimulusA = block.conditionStimulus[static_cast<std::size_t>(i)];
        t.stimulusB = block.conditionStimulus[static_cast<std::size_t>(j)];
        t.aOnLeft = random.coin();
        t.referenceStimulus = design.showReference ? block.referenceStimulus : -1;
        plan.push_back(t);
    }
    plan.insert(plan.end(), sequence.begin(), sequence.end());
    return plan;
}

} // namespace skinlab::experiments
