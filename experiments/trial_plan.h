#pragma once
// Per-participant trial plans. Order and sides come from a seeded generator (the seed is stored with the
// participant), following the design hygiene of docs/analysis.md (ITU-T P.910 practice):
//  - each pair appears in both orders (A left / A right): repetition k of a pair flips the side of repetition
//    k−1, and participant n+1 gets the mirror image of participant n's sides, so an even number of repetitions
//    balances sides within a participant and any two consecutive participants balance them exactly;
//  - hence each condition appears equally often left and right;
//  - practice trials come first; catch trials are spread evenly, one per equal segment of the test sequence,
//    never first, with the right answer alternating between left and right;
//  - the same pair is never shown twice in a row.
#include "analysis/scaling/responses.h"
#include "experiments/study_definition.h"

#include <cstdint>
#include <string>
#include <vector>

namespace skinlab::experiments {

// The trial kinds of analysis/scaling/responses.h (experiments sits above analysis): practice, test, repeat,
// catchTrial, named "practice", "test", "repeat", "catch" in the study file and its exports (contract 3).
using analysis::scaling::TrialKind;
using analysis::scaling::trialKindName;
TrialKind trialKindFromName(const std::string& name); // RuntimeError for a name the study file should not hold

// Stimulus index standing for the blank grey panel of a blank catch trial.
constexpr int kBlankStimulus = -1;

struct PlannedTrial {
    TrialKind kind = TrialKind::test;
    std::string block;
    std::string conditionA; // condition_A / condition_B of the responses export (contract 3)
    std::string conditionB; // "blank" for the panel of a blank catch trial
    int stimulusA = 0;
    int stimulusB = 0; // kBlankStimulus for a blank catch trial
    bool aOnLeft = true;
    int referenceStimulus = -1;
    char expected = 0; // 'A' or 'B' for catch trials, 0 otherwise
};

// Seed of participant number `participantIndex` (0, 1, 2, ... in order of joining) under the design seed.
std::uint64_t participantSeed(std::uint64_t designSeed, std::int64_t participantIndex);

// The participant's whole plan. For an active design (pairs = "active") the test trials are not known in advance:
// the plan holds `trials_per_participant` open slots (isActiveSlot) where the test trials go, with the practice
// and catch trials placed around them exactly as for a fixed design; experiments/active_plan.h fills the slots.
std::vector<PlannedTrial> planTrials(const StudyDefinition& study, std::int64_t participantIndex, std::uint64_t seed);

// An open test-trial slot of an active design's plan (empty block name; never stored).
inline bool isActiveSlot(const PlannedTrial& trial) { return trial.kind == TrialKind::test && trial.block.empty(); }

} // namespace skinlab::experiments
