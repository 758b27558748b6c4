#pragma once
// Power before recruiting (`skinlab study plan`): how many observers a design needs for the differences a truth
// predicts (e.g. ColorVideoVDP's JOD of every stimulus against its block's reference) to come out significant.
// Each block is simulated as the study would run it — every pair shown `repetitions` times to every observer,
// Thurstone observers (σ = 1.4826 per JOD, analysis/scaling/simulation.h) — and scaled with the project's own
// fit; a pair counts as resolved in a simulated study when its likelihood-ratio test (against the fit constrained
// to an equal pair), after
// Holm's correction over the block's pairs, is significant at α in the predicted direction. Power is the share of
// simulated studies that resolve it.
#include "experiments/simulated_observers.h"
#include "experiments/study_definition.h"

#include <cstdint>
#include <string>
#include <vector>

namespace skinlab::experiments {

struct PlanOptions {
    std::vector<int> observerCounts = {5, 10, 15, 20, 30, 40, 60, 80, 120};
    int simulations = 200; // simulated studies per observer count
    double alpha = 0.05;
    double power = 0.8;
    std::uint64_t seed = 1;
};

struct PlannedPair {
    std::string better, worse; // neighbours in predicted order
    double difference = 0.0;   // predicted JOD
    std::vector<double> power; // per observer count
};

struct PlannedBlock {
    std::string name;
    std::vector<std::string> conditions; // design order
    std::vector<double> predicted;       // JOD per condition
    std::vector<PlannedPair> neighbours; // sorted by predicted quality, best first
    int observersNeeded = -1;            // smallest count with every neighbour pair at the target power; -1: none
};

struct StudyPlan {
    PlanOptions options;
    std::vector<PlannedBlock> blocks;
    int repetitions = 1;
    int trialsPerObserver = 0; // what one observer answers in the design (practice, tests, repeats, catch)
};

// Throws InputError naming the truth's source when a condition has no predicted score.
StudyPlan planStudy(const StudyDefinition& definition, const SimulationTruth& truth, const PlanOptions& options);

std::string planText(const StudyPlan& plan);

} // namespace skinlab::experiments
