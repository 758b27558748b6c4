#pragma once
// `skinlab analyze validate`: a seeded simulation study of the scaling pipeline with known true scores
// (docs/analysis.md, "Validation"). Three scenarios per observer count:
//  - "thurstone": every observer follows the Case V model exactly (the model the intervals promise 95 % for);
//  - "lapses+side-bias": genuine observers with lapses and a per-observer side bias (model misspecification);
//  - "screening": the same genuine observers plus one random and one inverted observer; screening hit and
//    false-alarm rates, and the intervals after removing the flagged observers;
//  - "sparse": Case V observers who each judge only a random share of the pairs;
//  - "disconnected": Case V observers, the conditions in groups never compared with each other;
//  - "near-unanimous": Case V observers on a scale stretched so far pairs are (nearly) always unanimous;
//  - "active": Case V observers, one after another, each judging pairs the study server's active planner chose from every
//    earlier answer (pairs = "active" in a study); the coverage columns are those of the profile-likelihood intervals and
//    score tests, and the coverage of the studentized observer bootstrap (what `analyze scale` uses for an active
//    study) and of the union of both intervals are reported alongside.
#include "analysis/scaling/multiple_comparisons.h"
#include "analysis/scaling/pairwise_model.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace skinlab::analysis::scaling {

struct ValidationOptions {
    std::vector<double> trueScores = {0.0, 0.3, 0.9, 1.0, 1.8, 2.5}; // JOD
    std::vector<int> observerCounts = {10, 20, 30};
    int experiments = 200; // simulated experiments per scenario and observer count
    // Per observer and pair, each order 3 times (90 trials per observer for 6 conditions, ~8 minutes at 5 s a
    // trial). With 4, screening caught only 87 % of random observers at 10 observers (docs/analysis.md).
    int trialsPerPair = 6;
    int bootstrapSamples = 1000;
    std::uint64_t seed = 1;
    int threads = 2;
    double lapseRate = 0.02;                // "lapses+side-bias" and "screening" scenarios
    double sideBiasStandardDeviation = 0.3; // JOD
    int randomObservers = 1;                // "screening" scenario
    int invertedObservers = 1;              // "screening" scenario
    Correction correction = Correction::Holm;
    double alpha = 0.05;
    double screeningWhisker = 1.5;
    Prior prior = Prior::Gaussian;     // the prior the scores are fitted with (`analyze scale --prior`)
    double sparsePairFraction = 0.3;   // "sparse": share of the pairs each observer judges
    int disconnectedGroups = 2;        // "disconnected": groups of conditions, never compared across
    double nearUnanimousStretch = 3.0; // "near-unanimous": true scores multiplied by this
    std::vector<std::string> scenarios = {"thurstone", "lapses+side-bias", "screening",
                                          "sparse",    "disconnected",     "near-unanimous"};
    // "active": trials per observer (0: as many as the full design, trialsPerPair per pair), planned as the study
    // server plans them (analysis/scaling/active_sampling.h).
    int activeTrials = 0;
    double activeStretch = 1.0; // "active": true scores multiplied by this
};

// Every scenario runValidation knows.
const std::vector<std::string>& validationScenarios();

struct ValidationRow {
    std::string scenario;
    int observers = 0;
    int experiments = 0;
    double coverage = 0.0;      // the reported intervals (studentized, or the flagged fallback; an end the data leave
                                // open is open, as `analyze scale` reports it), 95 % nominal
    double pairCoverage = -1.0; // the same for every pair's difference (not "active")
    double oneSidedShare = 0.0; // share of score intervals with one open end
    double oneSidedCoverage = -1.0;     // how often the finite end of those held (−1: none)
    double pairOneSidedCoverage = -1.0; // the same for the pairs' intervals
    double meanWidth = 0.0;             // JOD
    double fallbackShare = 0.0;         // share of score intervals that fell back to percentile+profile
    double maximumHalfWidth = 0.0;      // JOD, largest distance from a score to one of its bounds
    double percentileCoverage = 0.0;    // pwcmp's percentile bootstrap on the same resamples
    double percentileMeanWidth = 0.0;
    double bootstrapCoverage = -1.0; // "active" only: the studentized observer bootstrap on the same data
    double unionCoverage = -1.0;     // "active" only: the union of that bootstrap and the profile interval
    double unionMeanWidth = 0.0;
    double rmse = 0.0;                // JOD, mean-zero scores against mean-zero truth
    double rankCorrelation = 0.0;     // mean Spearman ρ
    double significantCorrect = 0.0;  // fraction of (experiment, pair): significant with the true sign
    double significantReversed = 0.0; // fraction of (experiment, pair): significant with the wrong sign
    // screening scenario only (negative when not applicable)
    double randomHitRate = -1.0;
    double invertedHitRate = -1.0;
    double falseAlarmRate = -1.0;
};

struct ValidationReport {
    ValidationOptions options;
    std::vector<ValidationRow> rows;
    double seconds = 0.0;
};

ValidationReport runValidation(const ValidationOptions& options);
std::string validationMarkdown(const ValidationReport& report);
nlohmann::json validationJson(const ValidationReport& report);

} // namespace skinlab::analysis::scaling
