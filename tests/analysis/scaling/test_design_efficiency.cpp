// The asymptotic bound on what any choice of pairs can save over the full design (analysis/scaling/
// design_efficiency.h): the information of one comparison, and the A-optimal allocation's share against a brute
// force search.
#include "analysis/scaling/design_efficiency.h"
#include "analysis/scaling/pairwise_model.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

using namespace skinlab::analysis::scaling;

namespace {

// tr F(w)⁺ for three conditions and weights on the pairs (0,1), (0,2), (1,2).
double summedVariance(const std::vector<double>& truth, const double w[3]) {
    const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    Eigen::Matrix3d f = Eigen::Matrix3d::Constant(1.0 / 3.0);
    for (int p = 0; p < 3; ++p) {
        const int i = pairs[p][0], j = pairs[p][1];
        const double x = w[p] * comparisonInformation(truth[i] - truth[j]);
        f(i, i) += x, f(j, j) += x, f(i, j) -= x, f(j, i) -= x;
    }
    return f.inverse().trace() - 1.0;
}

} // namespace

TEST(DesignEfficiency, InformationOfOneComparison) {
    // 2/(π σ²) at a difference of 0; symmetric; falls with the distance.
    EXPECT_NEAR(comparisonInformation(0.0), 2.0 / (M_PI * kThurstoneSigma * kThurstoneSigma), 1e-12);
    EXPECT_NEAR(comparisonInformation(1.3), comparisonInformation(-1.3), 1e-15);
    EXPECT_GT(comparisonInformation(1.0), comparisonInformation(2.0));
    // Far apart (z > 8, where 1 − Φ(z) rounds to 0 in double): still tiny and positive, never huge.
    for (const double delta : {12.0, 15.0, 20.0, 30.0}) {
        EXPECT_GT(comparisonInformation(delta), 0.0) << delta;
        EXPECT_LT(comparisonInformation(delta), 1e-10) << delta;
        EXPECT_LT(comparisonInformation(-delta), 1e-10) << delta;
    }
    // Asymptotically I(δ) ≈ z φ(z) / σ² for large z (Mills' ratio).
    const double z = 10.0 / kThurstoneSigma;
    EXPECT_NEAR(comparisonInformation(10.0) / (z * std::exp(-0.5 * z * z) / std::sqrt(2.0 * M_PI)) * kThurstoneSigma *
                    kThurstoneSigma,
                1.0, 0.05);
}

TEST(DesignEfficiency, EqualScoresLeaveNothingToSave) {
    EXPECT_NEAR(optimalAllocationShare(std::vector<double>(8, 0.0)), 1.0, 1e-6);
    EXPECT_LE(optimalAllocationShare(std::vector<double>(8, 0.0)), 1.0 + 1e-12);
    EXPECT_EQ(optimalAllocationShare({0.0, 3.0}), 1.0);
}

TEST(DesignEfficiency, ShareMatchesABruteForceSearchOverAllocations) {
    for (const std::vector<double>& truth : {std::vector<double>{0.0, 1.0, 4.0}, std::vector<double>{0.0, 0.2, 0.4},
                                             std::vector<double>{-5.0, 0.0, 6.0}}) {
        const double uniform[3] = {1.0 / 3, 1.0 / 3, 1.0 / 3};
        const double full = summedVariance(truth, uniform);
        double best = std::numeric_limits<double>::infinity();
        const int steps = 400;
        for (int a = 1; a < steps; ++a)
            for (int b = 1; a + b < steps; ++b) {
                const double w[3] = {double(a) / steps, double(b) / steps, double(steps - a - b) / steps};
                best = std::min(best, summedVariance(truth, w) / full);
            }
        const double share = optimalAllocationShare(truth);
        EXPECT_LE(share, best + 1e-9) << truth[2]; // a lower bound on every allocation
        EXPECT_GE(share, best - 5e-3) << truth[2]; // and a tight one
        EXPECT_GT(share, 0.0);
    }
}

TEST(DesignEfficiency, WidelySpreadScoresGiveAShareBetweenZeroAndOne) {
    // 40 conditions spread over ±15 JOD: many pairs nearly unanimous, so an allocation to close pairs saves much,
    // but the share stays a share.
    std::vector<double> truth;
    for (int i = 0; i < 40; ++i) truth.push_back(-15.0 + 30.0 * i / 39.0);
    const double share = optimalAllocationShare(truth);
    EXPECT_GT(share, 0.0);
    EXPECT_LT(share, 0.5);
    std::vector<double> close;
    for (int i = 0; i < 40; ++i) close.push_back(0.02 * i);
    EXPECT_GT(optimalAllocationShare(close), 0.97);
    EXPECT_GT(optimalAllocationShare(close), share);
}
