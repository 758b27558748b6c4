#pragma once
// Confidence intervals and pairwise tests by a *studentized* bootstrap over observers (Efron & Tibshirani 1993,
// "An Introduction to the Bootstrap", ch. 12.5; Davison & Hinkley 1997, §5.2.1).
//
// pwcmp resamples observers and takes percentiles of the resampled scores; in simulation that covers the true
// scores only 87–93 % of the time at 10–30 observers (a percentile interval inherits the bootstrap's (n−1)/n
// variance shrinkage and the ML estimator's bias). Here each resample b is studentized:
//     t*_b = (q*_b − q̂) / se*_b,
// where se is the observer-cluster-robust ("sandwich") standard error computed from each observer's score
// contribution (Liang & Zeger 1986) — a variance estimated from the same n observers, so it shrinks with the
// resample and t* is close to pivotal. The interval is symmetric, q̂ ± |t|*_(level)·se (Hall 1988, Ann. Statist.
// 16:927), which reached 95 % coverage at 10 observers in simulation where the equal-tailed
// [q̂ − t*_(0.975)·se, q̂ − t*_(0.025)·se] stopped at 94.8 %. Differences q_i − q_j are handled the same way;
// their p-value is 2Φ(−|t_obs|·1.95996/|t|*_(0.95)), so p < 0.05 exactly when the 95 % interval excludes 0.
//
// Studentization needs a spread to divide by. Where it is degenerate — observers who all answer alike (se ≈ 0),
// resamples without spread (se* ≈ 0), extreme |t*|, a disconnected comparison graph, unanimous pairs (the win
// graph not strongly connected, Ford 1957) — a score or difference falls back, with its reasons recorded, to the
// hull of the percentile interval and the profile-posterior interval (profile_likelihood.h), and a difference's
// p-value to the score test. docs/analysis.md, "When the bootstrap is degenerate".
#include "analysis/scaling/comparison_data.h"
#include "analysis/scaling/pairwise_model.h"
#include "analysis/scaling/robust_variance.h"

#include <Eigen/Dense>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace skinlab::analysis::scaling {

struct BootstrapOptions {
    int samples = 1000;
    std::uint64_t seed = 1;
    int threads = 2;
    double level = 0.95; // two-sided confidence level
};

// Why an interval is not the studentized one (empty: it is). Names as written to scale.json.
struct IntervalDiagnosis {
    bool fallback = false;
    std::vector<std::string> reasons; // "disconnected", "unanimous", "observers-agree", "zero-spread-resamples",
                                      // "extreme-t", "bound-at-search-cap"
    // Which ends of the interval the data set (docs/analysis.md, "Intervals the data support"): "two-sided";
    // "lower" (the data bound it from below only: unanimous answers; the upper end is +∞), "upper", or "none"
    // (neither end: e.g. conditions in different components of a disconnected design, which cannot be compared), or
    // "not-measured" (a condition never compared). The finite end of a "lower" or "upper" interval is the profile
    // bound at oneSidedProfileThreshold (profile_likelihood.h) where that is farther out.
    std::string bound = "two-sided";
    // The point value is partly the prior's: an end the data leave open means the data do not fix the value
    // either (a unanimous distance is the prior's 4.96 JOD for 10:0). Marked wherever the value is shown.
    bool priorDriven = false;
};

struct DifferenceTest {
    int first = 0, second = 0; // condition indices, first < second
    double difference = 0.0;   // q_first − q_second (JOD)
    double standardError = 0.0;
    double low = 0.0, high = 0.0; // studentized interval of the difference (or the fallback, see diagnosis)
    double pValue = 1.0;          // two-sided, unadjusted (studentized, or the score test for a fallback)
    IntervalDiagnosis diagnosis;
    // pwcmp's construction on the same resamples: percentile interval of the resampled differences, and the
    // two-sided bootstrap p-value 2·min(share of resamples ≤ 0, share ≥ 0) (at least 1/B).
    double percentileLow = NAN, percentileHigh = NAN, percentilePValue = NAN;
};

// Structure of a block's comparison graph: connected components (pairs compared at least once) and strongly
// connected components of the win graph ("i beat j at least once"). Within a strongly connected component every
// difference has a finite ML estimate; across two, the data bound it on one side only.
struct DesignStructure {
    std::vector<int> component;         // per condition
    std::vector<int> stronglyConnected; // per condition
    int components = 0, stronglyConnectedComponents = 0;
};
DesignStructure designStructure(const BlockData& block);

struct BootstrapResult {
    int samples = 0;
    Eigen::VectorXd standardError;      // robust (sandwich) SE of each score
    Eigen::VectorXd low, high;          // studentized bootstrap interval, or the fallback (see scoreDiagnoses)
    Eigen::VectorXd modelStandardError; // from the posterior information (Fisher), for the diagnosis
    std::vector<IntervalDiagnosis> scoreDiagnoses; // per condition
    Eigen::VectorXd percentileLow, percentileHigh; // pwcmp's construction, for comparison only
    Eigen::VectorXd bootstrapMean;
    Eigen::MatrixXd bootstrapCovariance;
    std::vector<DifferenceTest> differences; // every pair i < j, compared or not
};

// Requires at least 2 observers. Deterministic for a given seed, whatever the thread count.
BootstrapResult bootstrapObservers(const BlockData& block, const FitResult& fit, const FitOptions& fitOptions,
                                   const BootstrapOptions& options);

// Quantile of sorted values, linear interpolation between order statistics (Hyndman & Fan type 7).
double sortedQuantile(const std::vector<double>& sorted, double probability);

// SplitMix64 (Steele, Lea & Flood 2014): derives independent per-task seeds from one user seed.
std::uint64_t mixSeed(std::uint64_t seed, std::uint64_t stream);

} // namespace skinlab::analysis::scaling
