#pragma once
// The trials of an active design (pairs = "active"), planned batch by batch while the study runs.
//
// A participant's plan is fixed at joining except for its test trials: planTrials() places practice trials first
// and catch trials among `trials_per_participant` open slots. Whenever the participant has answered every stored
// trial, the server stores the next stretch of the plan: the trials up to the next open slot, then one batch —
// the minimum spanning tree over 1/(expected variance reduction) of one block's posterior (active_sampling.h),
// built from every stored answer of every participant at that moment — in the open slots, then any trials up to
// the next open slot (so trailing catch trials come with the last batch). Trials are stored before they are
// shown; a stored trial is never re-planned, so a restart (the posterior is rebuilt from the stored answers)
// changes nothing already planned.
//
// Which block: the one where this participant has the fewest test trials relative to its batch size (m − 1),
// ties broken in a rotating order starting at the participant's index — so blocks alternate within a participant
// and participants starting together begin in different blocks. Sides: test trial k of participant n shows A on
// the left iff k + n is even (exact balance within a participant); which condition is A is a seeded coin.
// Within a batch, pairs come in decreasing order of gain; a batch never starts with the pair just shown.
#include "analysis/scaling/active_sampling.h"
#include "experiments/study_definition.h"
#include "experiments/trial_plan.h"

#include <cstdint>
#include <functional>
#include <vector>

namespace skinlab::experiments {

// Active sampling (the posterior, the batches) is the analysis library's.
namespace active = analysis::scaling::active;

// The trials to store next for a participant of an active design. `stored` = the participant's stored trials in
// position order (their positions are 0 … stored.size() − 1); `posteriorOf(b)` = the current posterior of
// study.blocks[b]. Empty when the plan is complete.
std::vector<PlannedTrial> nextActiveTrials(const StudyDefinition& study, std::int64_t participantIndex,
                                           std::uint64_t seed, const std::vector<PlannedTrial>& stored,
                                           const std::function<active::ScorePosterior(std::size_t)>& posteriorOf);

// Test answers of one block as comparisons for the posterior (condition indices of the block); `aSelected` per
// trial. Trials of other blocks or kinds are skipped.
// The options of the planner's posterior for a design: its prior N(0, active_prior_sd²) on every score.
active::PosteriorOptions plannerPosteriorOptions(const StudyDesign& design);

std::vector<active::Comparison> blockComparisons(const StudyBlock& block, const std::vector<PlannedTrial>& trials,
                                                 const std::vector<bool>& aSelected);

} // namespace skinlab::experiments
