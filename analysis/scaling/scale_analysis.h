#pragma once
// The whole pairwise analysis of a dataset (docs/analysis.md): per block, Thurstone Case V scores in JOD with
// studentized-bootstrap intervals, Bradley–Terry scores, pairwise tests with a multiple-comparison correction,
// design flags (disconnected graph, unanimous pairs, existence of the ML estimate), per-interval fallback flags, Kendall's ζ and u, side
// bias; per observer, held-out likelihood screening and catch-trial failures.
#include "analysis/scaling/bootstrap.h"
#include "analysis/scaling/comparison_data.h"
#include "analysis/scaling/consistency.h"
#include "analysis/scaling/multiple_comparisons.h"
#include "analysis/scaling/pairwise_model.h"
#include "analysis/scaling/screening.h"

#include <string>
#include <vector>

namespace skinlab::analysis::scaling {

// How the score intervals and pairwise tests are made. `bootstrap`: the studentized bootstrap over observers
// (profile likelihood with fewer than 2 observers). `profile`: profile-likelihood intervals and score tests for
// every block. `bootstrapAndProfile`: the union of the two intervals, a pair's p-value the larger of the two — the
// default for adaptive (active) designs, where each observer's pairs depend on earlier answers and neither interval
// alone covers 95 % at every number of observers (docs/analysis.md, "Validation of active designs").
// `percentile`: pwcmp's percentile bootstrap over observers (pw_scale_bootstrp), for comparison with pwcmp; its
// coverage is below nominal (docs/analysis.md).
enum class IntervalMethod { bootstrap, profile, percentile, bootstrapAndProfile };

// The default of a study's responses: bootstrapAndProfile for an adaptive design, bootstrap otherwise.
IntervalMethod defaultIntervals(bool adaptiveDesign);
// The method's name in scale.json's settings ("bootstrap", "profile", "percentile", "bootstrap+profile").
const char* intervalsName(IntervalMethod method);

struct AnalysisOptions {
    FitOptions fit; // fit.model is ignored: both models are always fitted
    IntervalMethod intervals = IntervalMethod::bootstrap;
    std::string intervalReason; // why `intervals` was chosen (e.g. "active design"), reported in scale.json
    BootstrapOptions bootstrap;
    Correction correction = Correction::Holm;
    double alpha = 0.05;           // significance level after correction
    double screeningWhisker = 1.5; // inter-quartile rule factor w
    bool pwcmpOutliers = false;    // also run pwcmp's outlier analysis (pw_outlier_analysis)
};

struct PairTest {
    DifferenceTest test;
    double comparisons = 0.0; // trials of this pair in the block (0: never compared directly)
    double adjustedPValue = 1.0;
    bool significant = false;
};

struct ObserverInBlock {
    double trials = 0.0;
    double heldOutLogLikelihood = 0.0; // nats, sum over the observer's trials
    TriadConsistency consistency;
    double sideTrials = 0.0;
    double leftChosen = 0.0;
};

struct BlockAnalysis {
    std::string name;
    std::vector<std::string> conditions;
    std::vector<std::string> observers;
    Eigen::MatrixXd counts; // D(i, j) = times i chosen over j
    FitResult thurstone;
    FitResult bradleyTerry;
    Eigen::VectorXd bradleyTerryStandardError;
    std::string intervalMethod; // "studentized-bootstrap", or "profile-likelihood" (fewer than 2 observers)
    std::vector<IntervalDiagnosis> intervalFlags; // per condition: fell back to percentile+profile, and why
    int bootstrapSamples = 0;
    Eigen::VectorXd standardError, low, high;      // Thurstone, JOD
    Eigen::VectorXd percentileLow, percentileHigh; // pwcmp-style percentile interval (reference only)
    std::vector<PairTest> pairs;                   // every i < j
    std::vector<std::vector<int>> components;      // connected components of the comparison graph
    bool mleExists = true; // win graph strongly connected (Ford 1957); otherwise the prior sets some distances
    std::vector<std::pair<int, int>> unanimousPairs; // compared pairs where one side never won
    // Per condition: compared at least once. A condition never compared has no score (its JOD is the prior's 0, its
    // interval the whole line): every output says "not measured" (bound "not-measured") instead of a number.
    std::vector<bool> measured;
    std::optional<double> kendallU;
    SideBias sideBias;
    std::vector<ObserverInBlock> observerStats;
    std::vector<std::string> warnings;
};

struct ObserverSummary {
    std::string observer;
    double trials = 0.0;
    double heldOutPerTrial = NAN; // mean held-out log-likelihood per trial over all blocks (nats)
    bool flagged = false;         // low outlier by the inter-quartile rule
    int catchTrials = 0;
    int catchFailures = 0;
    double sideTrials = 0.0;
    double leftChosen = 0.0;
    // Exact binomial test of the left rate = 1/2 over all the observer's trials with a known side (NaN without any);
    // `sideBiased` when it is significant after the analysis's correction over the observers tested, at its α.
    double sidePValue = NAN;
    double sidePAdjusted = NAN;
    bool sideBiased = false;
    // pwcmp's outlier analysis (AnalysisOptions::pwcmpOutliers): mean log10 binomial likelihood of the observer's
    // counts per compared pair under the leave-one-out scale (pwcmp's prior), and the distance below the first
    // quartile in inter-quartile ranges, dist_L = max(0, (Q1 − L)/IQR); pwcmp's rule flags dist_L > 1.5.
    double pwcmpLogLikelihood = NAN;
    double pwcmpDistance = NAN;
    bool pwcmpOutlier = false;
};

// pwcmp's outlier threshold on dist_L (examples/ex3_video_tmo_example.m).
inline constexpr double kPwcmpOutlierDistance = 1.5;

struct Analysis {
    std::string file;
    ResponseFormat format = ResponseFormat::SkinlabCsv;
    AnalysisOptions options;
    std::vector<BlockAnalysis> blocks;
    std::vector<ObserverSummary> observers;
    OutlierRule screeningRule;
    std::vector<ExcludedObserver> excluded; // observers the protocol's rule left out (not scaled)
    std::vector<std::string> warnings;      // every block's warnings too, prefixed by the block name
};

BlockAnalysis analyzeBlock(const BlockData& block, const AnalysisOptions& options);
Analysis analyzeDataset(const Dataset& dataset, const AnalysisOptions& options);

} // namespace skinlab::analysis::scaling
