#pragma once
// Consistency and agreement statistics of paired comparisons.
//  - Kendall's ζ (coefficient of consistence, Kendall & Babington Smith 1940): per observer, from the number of
//    circular triads c among m conditions; ζ = 1 − c/c_max, c_max = (m³ − m)/24 (m odd) or (m³ − 4m)/24 (m even).
//    c = m(m−1)(2m−1)/12 − ½ Σ a_i² with a_i = i's score (pairs won, ½ for a tied pair), valid when the observer
//    judged every pair. An observer's answers to a pair are reduced to the majority; equal counts are a tie (½).
//  - Kendall's u (coefficient of agreement, same paper): over all judgments of a block,
//    u = 2 Σ_pairs [C(a_ij, 2) + C(a_ji, 2)] / Σ_pairs C(N_ij, 2) − 1 (C = binomial coefficient), which reduces to
//    Kendall's formula for one judgment per observer and pair; u = 1 when every judgment agrees.
//  - Side (position) bias: b in JOD added to the left stimulus, P(first chosen | first on left) = F(d + b),
//    fitted by maximum likelihood with the scores held at their estimate. Its test is the exact binomial test of
//    "left chosen" against 1/2 (per block, and per observer in the screening): with the sides randomised or
//    balanced, an observer without side bias chooses the left image with probability 1/2 whatever the pair, and the
//    test stays valid where the Wald test of b breaks down (every answer on one side: b̂ = ±∞).
#include "analysis/scaling/comparison_data.h"
#include "analysis/scaling/pairwise_model.h"

#include <optional>

namespace skinlab::analysis::scaling {

struct TriadConsistency {
    bool complete = false;       // the observer judged every pair of the block
    double circularTriads = 0.0; // c (can be fractional with ties)
    double maximumTriads = 0.0;  // c_max
    std::optional<double> zeta;  // 1 − c/c_max; absent if incomplete or m < 3
};
TriadConsistency kendallZeta(const BlockData& block, int observer);

std::optional<double> kendallU(const BlockData& block); // absent when no pair has ≥ 2 judgments

struct SideBias {
    bool available = false; // trials with a known side exist
    double trials = 0.0;
    double leftRate = 0.0; // fraction of those trials answered "left"
    double leftChosen = 0.0;
    double bias = 0.0; // JOD added to the left stimulus (positive: left preferred); ±∞ when every answer was on
                       // one side (the likelihood grows without bound: no finite estimate)
    double standardError = 0.0; // NaN where the estimate is not finite
    double pValue = 1.0;        // two-sided exact binomial test of the left rate = 1/2
};
SideBias estimateSideBias(const BlockData& block, const Eigen::VectorXd& scores, Model model);

// Two-sided exact binomial test of `successes` out of `trials` against probability 1/2: the probability of an
// outcome at least as far from trials/2, 2·P(X ≤ min(k, n − k)) capped at 1 (counts rounded to integers; 1 without
// trials).
double binomialHalfPValue(double successes, double trials);

} // namespace skinlab::analysis::scaling
