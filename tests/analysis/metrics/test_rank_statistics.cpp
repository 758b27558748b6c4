// The statistics of ranking agreement (docs/pathtraced.md, "Reading the agreement"): t quantiles against published
// tables, sample quantiles against numpy, Tukey's fence, the resampled pair means, and τ_b's intervals — the seed
// jackknife with the t quantile, and the bootstrap over conditions and seeds, whose coverage of a population's τ is
// measured on synthetic conditions with many seeds.
#include "analysis/metrics/debiased_error.h"
#include "analysis/metrics/rank_statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace skinlab::metrics {
namespace {

TEST(RankStatistics, StudentTQuantilesMatchPublishedTables) {
    // Two-sided 95 % (p = 0.975) and 99 % (p = 0.995) critical values, e.g. NIST/SEMATECH e-Handbook, Table 1.3.6.7.2.
    EXPECT_NEAR(studentTQuantile(0.975, 1), 12.706, 1e-3);
    EXPECT_NEAR(studentTQuantile(0.975, 2), 4.303, 1e-3);
    EXPECT_NEAR(studentTQuantile(0.975, 3), 3.182, 1e-3);
    EXPECT_NEAR(studentTQuantile(0.975, 7), 2.365, 1e-3);
    EXPECT_NEAR(studentTQuantile(0.975, 10), 2.228, 1e-3);
    EXPECT_NEAR(studentTQuantile(0.995, 3), 5.841, 1e-3);
    EXPECT_NEAR(studentTQuantile(0.975, 1e7), 1.95996, 1e-4); // the normal quantile
    EXPECT_NEAR(studentTQuantile(0.025, 3), -studentTQuantile(0.975, 3), 1e-12);
    EXPECT_DOUBLE_EQ(studentTQuantile(0.5, 4), 0.0);
    EXPECT_NEAR(studentTCdf(studentTQuantile(0.9, 5), 5), 0.9, 1e-12);
    EXPECT_NEAR(studentTCdf(1.0, 1), 0.75, 1e-12); // Cauchy: 1/2 + atan(1)/π
    EXPECT_TRUE(std::isnan(studentTQuantile(1.0, 3)));
    EXPECT_TRUE(std::isnan(studentTQuantile(0.975, 0)));
}

TEST(RankStatistics, QuantilesIntervalsFencesAndTheSmallest) {
    // numpy.quantile([1, 2, 3, 4], [0.25, 0.5, 0.9]) = [1.75, 2.5, 3.7]
    EXPECT_DOUBLE_EQ(sampleQuantile({4, 1, 3, 2}, 0.25), 1.75);
    EXPECT_DOUBLE_EQ(sampleQuantile({4, 1, 3, 2}, 0.5), 2.5);
    EXPECT_NEAR(sampleQuantile({4, 1, 3, 2, NAN}, 0.9), 3.7, 1e-12);
    EXPECT_TRUE(std::isnan(sampleQuantile({}, 0.5)));
    std::vector<double> replicates;
    for (int i = 0; i <= 100; ++i) replicates.push_back(i);
    const auto interval = percentileInterval(replicates, 0.95);
    EXPECT_NEAR(interval[0], 2.5, 1e-9);
    EXPECT_NEAR(interval[1], 97.5, 1e-9);
    // Q1 = 3, Q3 = 7: the fence is 7 + 1.5·4 = 13, so 100 is clearly worse and 8 is not.
    EXPECT_DOUBLE_EQ(upperTukeyFence({1, 2, 3, 4, 5, 6, 7, 8, 100}), 13.0);
    EXPECT_TRUE(std::isnan(upperTukeyFence({1, 2, 3})));
    EXPECT_EQ(smallestIndices({5, 1, NAN, 3, 1}, 3), (std::vector<std::size_t>{1, 4, 3}));
    EXPECT_EQ(smallestIndices({2, 1}, 16), (std::vector<std::size_t>{1, 0}));
}

TEST(RankStatistics, PairTermsResampleWithoutTheSquaresOfOneSeed) {
    // Three seeds: P_01 = 1, P_02 = 2, P_12 = 3.
    const std::vector<double> terms{1, 2, 3};
    EXPECT_DOUBLE_EQ(pairTermMean(terms, 3, {0, 1, 2}), 2.0);
    EXPECT_DOUBLE_EQ(pairTermMean(terms, 3, {0, 1}), 1.0);    // leave seed 2 out
    EXPECT_DOUBLE_EQ(pairTermMean(terms, 3, {2, 1}), 3.0);    // order does not matter
    EXPECT_DOUBLE_EQ(pairTermMean(terms, 3, {0, 0, 1}), 1.0); // the pair (0, 0) is no pair of independent seeds
    EXPECT_DOUBLE_EQ(pairTermMean(terms, 3, {0, 2, 2}), 2.0);
    EXPECT_TRUE(std::isnan(pairTermMean(terms, 3, {1, 1})));
}

// Synthetic conditions: each has a true error field s_c · u_c,p over P pixels (u = ±1 at random, so its true MSE
// is s_c²), and the seeds add noise n_k,p shared by all conditions, as Cycles' seeds are. `other` is the other
// truth's score.
struct Synthetic {
    std::vector<DebiasedScores> scores;
    std::vector<double> other;
};

Synthetic synthesize(const std::vector<double>& scale, const std::vector<double>& other, std::size_t seeds,
                     double noise, std::mt19937_64& random) {
    constexpr std::size_t pixels = 40;
    std::normal_distribution<double> normal(0.0, 1.0);
    std::bernoulli_distribution sign(0.5);
    std::vector<std::vector<double>> seedNoise(seeds, std::vector<double>(pixels));
    for (auto& seed : seedNoise)
        for (double& n : seed) n = noise * normal(random);
    Synthetic synthetic;
    synthetic.other = other;
    for (double s : scale) {
        // Each condition errs in its own pattern of signs, so the seeds' noise moves each error differently.
        std::vector<double> shape(pixels);
        for (double& u : shape) u = sign(random) ? 1.0 : -1.0;
        DebiasedScores scores;
        scores.seeds = seeds;
        std::vector<double> terms;
        for (std::size_t i = 0; i < seeds; ++i)
            for (std::size_t j = i + 1; j < seeds; ++j) {
                double sum = 0.0;
                for (std::size_t p = 0; p < pixels; ++p)
                    sum += (s * shape[p] - seedNoise[i][p]) * (s * shape[p] - seedNoise[j][p]);
                terms.push_back(sum / pixels);
            }
        scores.pairTerms[0][4] = terms;
        synthetic.scores.push_back(scores);
    }
    return synthetic;
}

std::vector<std::size_t> everyIndex(std::size_t count) {
    std::vector<std::size_t> all(count);
    for (std::size_t i = 0; i < count; ++i) all[i] = i;
    return all;
}

TEST(RankStatistics, JackknifeIntervalUsesTheTQuantileOfSeedsMinusOne) {
    std::mt19937_64 random(7);
    // Errors close together against much noise: leaving a seed out reorders some of them.
    const Synthetic synthetic = synthesize({0.30, 0.31, 0.32, 0.33, 0.34, 0.35}, {1, 3, 2, 4, 6, 5}, 4, 0.3, random);
    const TruthScore truth{4, 0, TruthKind::mse};
    const RankingAgreement agreement =
        rankingAgreement(synthetic.scores, synthetic.other, truth, everyIndex(6), AgreementOptions{});
    EXPECT_NEAR(agreement.tQuantile, 3.182446, 1e-5); // not 1.96: four seeds, three degrees of freedom
    ASSERT_GT(agreement.tau.standardError, 0.0);
    const double half = agreement.tQuantile * agreement.tau.standardError;
    EXPECT_NEAR(agreement.jackknifeInterval[0], std::max(-1.0, agreement.tau.value - half), 1e-12);
    EXPECT_NEAR(agreement.jackknifeInterval[1], std::min(1.0, agreement.tau.value + half), 1e-12);
    ASSERT_TRUE(std::isfinite(agreement.bootstrapInterval[0]) && std::isfinite(agreement.bootstrapInterval[1]));
    EXPECT_LT(agreement.bootstrapInterval[0], agreement.bootstrapInterval[1]);
}

TEST(RankStatistics, CompetitiveSubsetsAreTheClosestAndWithoutTheClearlyWorse) {
    // Ten conditions: eight agree with the other truth, the two worst are far off and ranked best by it.
    std::vector<double> scale;
    std::vector<double> other;
    for (int c = 0; c < 8; ++c) {
        scale.push_back(0.10 + 0.01 * c);
        other.push_back(c);
    }
    scale.push_back(1.0);
    other.push_back(-2);
    scale.push_back(1.1);
    other.push_back(-1);
    std::mt19937_64 random(11);
    const Synthetic synthetic = synthesize(scale, other, 6, 0.001, random);
    AgreementOptions options;
    options.competitiveCount = 8;
    const AgreementSubsets subsets =
        agreementSubsets(synthetic.scores, synthetic.other, {4, 0, TruthKind::mse}, options);
    EXPECT_EQ(subsets.all.conditions, 10u);
    EXPECT_LT(subsets.all.tau.value, 0.5);
    EXPECT_EQ(subsets.competitive.members, (std::vector<std::size_t>{0, 1, 2, 3, 4, 5, 6, 7}));
    EXPECT_NEAR(subsets.competitive.tau.value, 1.0, 1e-12);
    EXPECT_EQ(subsets.withoutClearlyWorse.conditions, 8u);
    EXPECT_GT(subsets.clearlyWorseFence, 0.17 * 0.17);
    EXPECT_LT(subsets.clearlyWorseFence, 1.0);
}

TEST(RankStatistics, BootstrapOverConditionsCoversThePopulationTauWhereTheSeedJackknifeDoesNot) {
    // 24 conditions drawn from a population in which the other truth's score x and the log of the true error are
    // bivariate normal with correlation ρ, so the population's τ is (2/π)·asin ρ (Kendall's τ of a bivariate
    // normal); eight seeds with little noise. The seed jackknife measures only the seeds' noise; the conditions are
    // a sample, and only the bootstrap over them covers the population's τ.
    const double rho = 0.7;
    const double populationTau = 2.0 / std::numbers::pi * std::asin(rho);
    const int experiments = 60;
    AgreementOptions options;
    options.bootstrapReplicates = 500;
    int bootstrapCovered = 0;
    int jackknifeCovered = 0;
    std::mt19937_64 random(2024);
    std::normal_distribution<double> normal(0.0, 1.0);
    for (int experiment = 0; experiment < experiments; ++experiment) {
        std::vector<double> scale;
        std::vector<double> other;
        for (int c = 0; c < 24; ++c) {
            const double x = normal(random);
            const double z = rho * x + std::sqrt(1.0 - rho * rho) * normal(random);
            other.push_back(x);
            scale.push_back(0.1 * std::exp(0.3 * z));
        }
        const Synthetic synthetic = synthesize(scale, other, 8, 0.002, random);
        options.bootstrapSeed = static_cast<std::uint64_t>(experiment);
        const RankingAgreement agreement =
            rankingAgreement(synthetic.scores, synthetic.other, {4, 0, TruthKind::mse}, everyIndex(24), options);
        if (agreement.bootstrapInterval[0] <= populationTau && populationTau <= agreement.bootstrapInterval[1])
            ++bootstrapCovered;
        if (agreement.jackknifeInterval[0] <= populationTau && populationTau <= agreement.jackknifeInterval[1])
            ++jackknifeCovered;
    }
    EXPECT_GE(bootstrapCovered, 51) << "bootstrap intervals covered the population's tau in " << bootstrapCovered
                                    << " of " << experiments;
    EXPECT_LE(jackknifeCovered, 30) << "seed-jackknife intervals covered it in " << jackknifeCovered << " of "
                                    << experiments;
}

} // namespace
} // namespace skinlab::metrics
