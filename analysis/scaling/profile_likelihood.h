#pragma once
// Model-based intervals and tests that stay valid where an observer bootstrap cannot (docs/analysis.md,
// "When the bootstrap is degenerate"): all observers answering alike, unanimous pairs, disconnected designs,
// count matrices without observers.
//  - Profile interval (Cox & Hinkley 1974, §7.2; Venzon & Moolgavkar 1988): for a contrast θ = aᵀq, the values c
//    with 2·(L̂ − max_{aᵀq = c} L(q)) ≤ χ²₁(level), L the log posterior (the likelihood under the weak prior).
//    Asymmetric where the data are: a unanimous pair bounds its difference from below by the data and from above
//    by the prior only.
//  - Score test (Rao 1948) of q_i = q_j at the constrained maximum, with the larger of the model-based and the
//    observer-cluster-robust variance of the score. On a two-condition block it is the binomial z-test, which
//    agrees with the exact binomial test (docs/analysis.md gives the figures).
#include "analysis/scaling/comparison_data.h"
#include "analysis/scaling/pairwise_model.h"
#include "analysis/scaling/robust_variance.h"

#include <Eigen/Dense>

namespace skinlab::analysis::scaling {

// Bounds farther than this from the estimate are not searched for: the bound is reported at the cap, flagged.
inline constexpr double kProfileSearchCap = 200.0; // JOD

struct ProfileInterval {
    double low = 0.0, high = 0.0;
    bool lowAtCap = false, highAtCap = false; // the posterior did not fall enough within kProfileSearchCap
};

// Profile interval of θ = aᵀq at the given two-sided level; `fit` is the unconstrained maximum of `counts`.
// Bounded time: at most ~60 constrained fits per bound.
ProfileInterval profileInterval(const PairCounts& counts, const FitOptions& options, const FitResult& fit,
                                const Eigen::VectorXd& contrast, double level);

// One end of a profile interval: the value of θ = aᵀq on `side` (−1: below the estimate, +1: above) where twice the
// fall of the log posterior from its maximum reaches `threshold`. `atCap`: not reached within kProfileSearchCap.
double profileBound(const PairCounts& counts, const FitOptions& options, const FitResult& fit,
                    const Eigen::VectorXd& contrast, int side, double threshold, bool* atCap = nullptr);

// The threshold for the one end of an interval whose other end the data leave open (unanimous answers,
// docs/analysis.md, "Intervals the data support"): −2·log((1 − level)/2), 7.38 at 95 %. For one pair answered
// n:0 the profile likelihood ratio is then exactly the probability of n:0, so the bound is the exact
// (Clopper–Pearson) one-sided bound at (1 + level)/2; χ²₁(level) = 3.84 would give p ≥ 0.825 for 10:0, which a
// true p of 0.80 produces 11 % of the time.
double oneSidedProfileThreshold(double level);

// Two-sided p-value of the score test of q_first = q_second. `block` supplies the observers for the robust
// variance (nullptr: model-based only, e.g. a count matrix).
double scoreTestPValue(const BlockData* block, const PairCounts& counts, const FitOptions& options,
                       const FitResult& fit, int first, int second);

} // namespace skinlab::analysis::scaling
