// Known answers of the scaling: pwcmp's oracle, the 75 % = 1 JOD anchor, unanimous and disconnected designs,
// Kendall's coefficients, Holm's correction.
#include "analysis/scaling/consistency.h"
#include "analysis/scaling/multiple_comparisons.h"
#include "analysis/scaling/pairwise_model.h"
#include "analysis/scaling/scale_analysis.h"

#include <gtest/gtest.h>

#include <cmath>

namespace skinlab::analysis::scaling {
namespace {

// A block from a count matrix, one pseudo-observer (as a count-matrix file).
BlockData matrixBlock(const std::vector<std::vector<double>>& counts) {
    BlockData block;
    block.name = "test";
    block.hasObservers = false;
    block.observers = {"(count matrix)"};
    const int m = static_cast<int>(counts.size());
    for (int i = 0; i < m; ++i) block.conditions.push_back("c" + std::to_string(i));
    std::vector<double> first, second;
    for (int i = 0; i < m; ++i)
        for (int j = i + 1; j < m; ++j)
            if (counts[i][j] + counts[j][i] > 0) {
                block.pairs.emplace_back(i, j);
                first.push_back(counts[i][j]);
                second.push_back(counts[j][i]);
            }
    const auto p = static_cast<Eigen::Index>(first.size());
    block.winsFirst = Eigen::Map<Eigen::RowVectorXd>(first.data(), p);
    block.winsSecond = Eigen::Map<Eigen::RowVectorXd>(second.data(), p);
    block.sideCounts.assign(first.size(), {0, 0, 0, 0});
    block.leftChosen = Eigen::VectorXd::Zero(1);
    block.sideTrials = Eigen::VectorXd::Zero(1);
    return block;
}

TEST(PairwiseModel, PwcmpOracleGivesMinusOneZeroOne) {
    // pwcmp's own example: D = [[0,25,0],[75,0,25],[0,75,0]] ⇒ q = [−1, 0, 1] JOD. The prior (precision 0.002)
    // moves the answer by 2.5e-4; the tolerance is 1e-3.
    const BlockData block = matrixBlock({{0, 25, 0}, {75, 0, 25}, {0, 75, 0}});
    const FitResult fit = fitScores(block.totalCounts(), FitOptions{});
    ASSERT_TRUE(fit.converged);
    EXPECT_NEAR(fit.scores[0], -1.0, 1e-3);
    EXPECT_NEAR(fit.scores[1], 0.0, 1e-3);
    EXPECT_NEAR(fit.scores[2], 1.0, 1e-3);
}

TEST(PairwiseModel, SeventyFiveToTwentyFiveIsOneJod) {
    for (Model model : {Model::Thurstone, Model::BradleyTerry}) {
        const BlockData block = matrixBlock({{0, 75}, {25, 0}});
        FitOptions options;
        options.model = model;
        const FitResult fit = fitScores(block.totalCounts(), options);
        // The default prior on a pair with 100 trials shrinks the difference by ~5e-5 JOD.
        EXPECT_NEAR(fit.scores[0] - fit.scores[1], 1.0, 1e-3) << modelName(model);
        EXPECT_NEAR(fit.scores.sum(), 0.0, 1e-12) << "the scale's mean is fixed at 0";
        EXPECT_NEAR(preferenceProbability(model, 1.0), 0.75, 1e-4) << modelName(model);
    }
}

TEST(PairwiseModel, WithoutPriorTheOracleIsExact) {
    FitOptions options;
    options.priorPrecision = 0.0;
    const BlockData block = matrixBlock({{0, 25, 0}, {75, 0, 25}, {0, 75, 0}});
    const FitResult fit = fitScores(block.totalCounts(), options);
    // Φ(1/1.4826) = 0.7500003: the ML difference is 1 JOD to ~1e-6.
    EXPECT_NEAR(fit.scores[2] - fit.scores[1], 1.0, 1e-5);
    EXPECT_NEAR(fit.scores[1] - fit.scores[0], 1.0, 1e-5);
}

TEST(PairwiseModel, UnanimousAnswersGiveFiniteFlaggedScores) {
    const BlockData block = matrixBlock({{0, 10, 10}, {0, 0, 7}, {0, 3, 0}});
    const BlockAnalysis result = analyzeBlock(block, AnalysisOptions{});
    ASSERT_TRUE(result.thurstone.converged);
    for (int i = 0; i < 3; ++i) EXPECT_TRUE(std::isfinite(result.thurstone.scores[i]));
    // c0 won every answer: the data bound its score from below only ("at least"); c1 and c2 never beat c0, so
    // theirs only from above. The other ends would be set by the prior: they are left open.
    EXPECT_EQ(result.intervalFlags[0].bound, "lower");
    EXPECT_TRUE(std::isfinite(result.low[0]) && result.low[0] > 0.0 && std::isinf(result.high[0]));
    for (int i = 1; i < 3; ++i) {
        EXPECT_EQ(result.intervalFlags[i].bound, "upper") << i;
        EXPECT_TRUE(std::isinf(result.low[i]) && std::isfinite(result.high[i])) << i;
    }
    EXPECT_FALSE(result.mleExists);
    EXPECT_EQ(result.unanimousPairs.size(), 2u);
    EXPECT_GT(result.thurstone.scores[0], result.thurstone.scores[1] + 1.0); // c0 won everything
    EXPECT_LT(result.thurstone.scores[0] - result.thurstone.scores[1], 8.0); // bounded by the prior
    ASSERT_FALSE(result.warnings.empty());
    EXPECT_NE(result.warnings.front().find("unanimous"), std::string::npos);
}

TEST(PairwiseModel, DisconnectedDesignGivesFiniteFlaggedScores) {
    // {c0, c1} and {c2, c3} never compared with each other.
    const BlockData block = matrixBlock({{0, 30, 0, 0}, {10, 0, 0, 0}, {0, 0, 0, 20}, {0, 0, 20, 0}});
    const BlockAnalysis result = analyzeBlock(block, AnalysisOptions{});
    ASSERT_EQ(result.components.size(), 2u);
    EXPECT_EQ(result.components[0], (std::vector<int>{0, 1}));
    EXPECT_EQ(result.components[1], (std::vector<int>{2, 3}));
    for (int i = 0; i < 4; ++i) EXPECT_TRUE(std::isfinite(result.thurstone.scores[i]));
    // Within a component the data decide (30:10 ≈ 1 JOD); across components only the prior (centred).
    EXPECT_NEAR(result.thurstone.scores[0] - result.thurstone.scores[1], 1.0, 0.01);
    EXPECT_NEAR(result.thurstone.scores[2] - result.thurstone.scores[3], 0.0, 1e-9);
    ASSERT_FALSE(result.warnings.empty());
    EXPECT_NE(result.warnings.front().find("disconnected ({c0,c1} {c2,c3})"), std::string::npos)
        << result.warnings.front();
}

// A block with observers, each answering every pair once, all by the order c0 ≻ c1 ≻ c2 ≻ c3.
BlockData unanimousObservers(int observers, int conditions) {
    BlockData block;
    block.name = "unanimous";
    for (int i = 0; i < conditions; ++i) block.conditions.push_back("c" + std::to_string(i));
    for (int k = 0; k < observers; ++k) block.observers.push_back("o" + std::to_string(k));
    for (int i = 0; i < conditions; ++i)
        for (int j = i + 1; j < conditions; ++j) block.pairs.emplace_back(i, j);
    const auto p = static_cast<Eigen::Index>(block.pairs.size());
    block.winsFirst = Eigen::MatrixXd::Ones(observers, p);
    block.winsSecond = Eigen::MatrixXd::Zero(observers, p);
    block.sideCounts.assign(block.pairs.size(), {0, 0, 0, 0});
    block.leftChosen = Eigen::VectorXd::Zero(observers);
    block.sideTrials = Eigen::VectorXd::Zero(observers);
    return block;
}

TEST(Consistency, KendallUIsOneForUnanimousObservers) {
    const BlockData block = unanimousObservers(8, 4);
    ASSERT_TRUE(kendallU(block).has_value());
    EXPECT_DOUBLE_EQ(*kendallU(block), 1.0);
}

TEST(Consistency, KendallUOfAnEvenSplitIsMinimal) {
    // Two observers who disagree on every pair: no agreeing pair of judgments ⇒ u = 2·0/1 − 1 = −1.
    BlockData block = unanimousObservers(2, 3);
    block.winsFirst.row(1).setZero();
    block.winsSecond.row(1).setOnes();
    EXPECT_DOUBLE_EQ(*kendallU(block), -1.0);
}

TEST(Consistency, KendallZetaCountsCircularTriads) {
    BlockData block = unanimousObservers(2, 3);
    // Observer 1: c0 ≻ c1, c1 ≻ c2, c2 ≻ c0 — one circular triad, the maximum for m = 3 ((27 − 3)/24 = 1).
    block.winsFirst.row(1) << 1, 0, 1; // pairs (0,1), (0,2), (1,2)
    block.winsSecond.row(1) << 0, 1, 0;
    const TriadConsistency consistent = kendallZeta(block, 0);
    const TriadConsistency circular = kendallZeta(block, 1);
    ASSERT_TRUE(consistent.zeta && circular.zeta);
    EXPECT_DOUBLE_EQ(*consistent.zeta, 1.0);
    EXPECT_DOUBLE_EQ(circular.circularTriads, 1.0);
    EXPECT_DOUBLE_EQ(*circular.zeta, 0.0);
}

TEST(MultipleComparisons, HolmMatchesHandComputedValues) {
    // p = (0.01, 0.04, 0.03, 0.005): sorted 0.005·4 = 0.02, 0.01·3 = 0.03, 0.03·2 = 0.06, 0.04·1 → max 0.06.
    const std::vector<double> adjusted = adjustPValues({0.01, 0.04, 0.03, 0.005}, Correction::Holm);
    EXPECT_NEAR(adjusted[0], 0.03, 1e-12);
    EXPECT_NEAR(adjusted[1], 0.06, 1e-12);
    EXPECT_NEAR(adjusted[2], 0.06, 1e-12);
    EXPECT_NEAR(adjusted[3], 0.02, 1e-12);
    EXPECT_NEAR(adjustPValues({0.3, 0.01}, Correction::Bonferroni)[0], 0.6, 1e-12);
}

} // namespace
} // namespace skinlab::analysis::scaling
