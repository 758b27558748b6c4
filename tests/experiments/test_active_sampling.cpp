// Unit tests of active sampling (analysis/scaling/active_sampling.h, experiments/active_plan.h): the EP posterior
// recovers known scores from simulated answers and does not depend on the answers' order; the information gain
// prefers close, uncertain pairs; a batch is a spanning tree (connected, m − 1 pairs) and reproducible from its
// seed; the `pairs = "active"` design keys are checked strictly; an active plan keeps practice and catch trials
// in place and fills its open slots batch by batch.
#include "common/error.h"
#include "analysis/scaling/active_sampling.h"
#include "experiments/active_plan.h"
#include "common/seeded_random.h"
#include "experiments/study_definition.h"
#include "stimulus_set_fixture.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <cmath>
#include <numeric>
#include <random>
#include <set>

using namespace skinlab::experiments;
using namespace skinlab::analysis::scaling::active;
using skinlab::combineSeed;
using skinlab::SeededRandom;
using skinlab::experiments::test_support::TempFolder;

namespace {

// Thurstone observer (docs/analysis.md): i beats j iff q_i + ε_i > q_j + ε_j, ε ~ N(0, σ²/2).
std::vector<Comparison> simulate(const std::vector<double>& truth, int perPair, std::uint64_t seed) {
    std::mt19937_64 random(seed);
    std::normal_distribution<double> noise(0.0, kThurstoneSigma / std::sqrt(2.0));
    std::vector<Comparison> out;
    const int m = static_cast<int>(truth.size());
    for (int r = 0; r < perPair; ++r)
        for (int i = 0; i < m; ++i)
            for (int j = i + 1; j < m; ++j) {
                const bool iWins = truth[static_cast<std::size_t>(i)] + noise(random) >
                                   truth[static_cast<std::size_t>(j)] + noise(random);
                out.push_back(iWins ? Comparison{i, j} : Comparison{j, i});
            }
    return out;
}

bool connected(int m, const std::vector<std::pair<int, int>>& edges) {
    std::vector<int> parent(static_cast<std::size_t>(m));
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](int x) {
        while (parent[static_cast<std::size_t>(x)] != x)
            x = parent[static_cast<std::size_t>(x)] =
                parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
        return x;
    };
    for (const auto& [a, b] : edges) parent[static_cast<std::size_t>(find(a))] = find(b);
    for (int i = 1; i < m; ++i)
        if (find(i) != find(0)) return false;
    return true;
}

StudyDefinition makeStudy(const std::string& designToml) {
    TempFolder folder("active");
    test_support::writeStimulusSet(folder.path(), {});
    return resolveStudy(parseStudyDesign(designToml, "D.toml"), readStimulusManifest(folder.path()));
}

std::string designError(const std::string& designToml) {
    try {
        parseStudyDesign(designToml, "D.toml");
    } catch (const skinlab::InputError& e) {
        return e.what();
    }
    return "(no error)";
}

} // namespace

TEST(ActiveSampling, PosteriorConvergesToTheTrueScores) {
    const std::vector<double> truth = {-1.5, -0.8, 0.0, 0.3, 0.9, 1.1};
    double previousError = 1e9, previousSd = 1e9;
    for (const int perPair : {5, 40, 300}) {
        const ScorePosterior p = fitPosterior(6, simulate(truth, perPair, 42));
        EXPECT_TRUE(p.converged) << perPair;
        const double meanOfMeans = std::accumulate(p.mean.begin(), p.mean.end(), 0.0) / 6.0;
        double squared = 0.0, sd = 0.0;
        for (std::size_t i = 0; i < 6; ++i) {
            squared += std::pow(p.mean[i] - meanOfMeans - truth[i], 2);
            // sd of the centred score q_i − q̄ (the common offset is left to the prior: answers say nothing on it)
            double centred = p.variance(static_cast<int>(i));
            for (int j = 0; j < 6; ++j) {
                centred -= 2.0 / 6.0 * p.cov(static_cast<int>(i), j);
                for (int k = 0; k < 6; ++k) centred += p.cov(j, k) / 36.0;
            }
            sd += std::sqrt(centred) / 6.0;
        }
        const double rmse = std::sqrt(squared / 6.0);
        EXPECT_LT(rmse, previousError * 1.05) << perPair << " answers per pair";
        EXPECT_LT(sd, previousSd) << "more answers, narrower posterior";
        previousError = rmse;
        previousSd = sd;
    }
    EXPECT_LT(previousError, 0.1) << "4500 answers pin the scores to a few hundredths of a JOD";
    EXPECT_LT(previousError, 2 * previousSd) << "the error is of the order of the posterior sd";
    // The posterior sd at 300 answers per pair is the order of the ML standard error (~0.05 JOD).
    EXPECT_LT(previousSd, 0.1);
    EXPECT_GT(previousSd, 0.01);
}

// The empirical-Bayes prior follows the spread of the answers: near the spread of widely spaced true scores (sd
// about 2.4 JOD here), at its floor for scores within a JOD, the fixed prior when there are no answers; and its
// posterior means are farther apart than the fixed sd-1 prior's (less shrinkage).
TEST(ActiveSampling, EmpiricalPriorFollowsTheSpreadOfTheAnswers) {
    PosteriorOptions empirical;
    empirical.empiricalPrior = true;
    const std::vector<double> wide = {-4.0, -2.0, -0.5, 0.5, 2.0, 4.0};
    const ScorePosterior spread = fitPosterior(6, simulate(wide, 20, 7), empirical);
    const double trueVariance = std::inner_product(wide.begin(), wide.end(), wide.begin(), 0.0) / 6.0; // 7.08
    EXPECT_GT(spread.priorVariance, 0.6 * trueVariance);
    EXPECT_LE(spread.priorVariance, empirical.maxPriorVariance);
    const ScorePosterior fixed = fitPosterior(6, simulate(wide, 20, 7));
    EXPECT_EQ(fixed.priorVariance, 1.0);
    EXPECT_GT(spread.mean[5] - spread.mean[0], fixed.mean[5] - fixed.mean[0]);

    const std::vector<double> close = {-0.3, -0.1, 0.0, 0.1, 0.2, 0.3};
    EXPECT_EQ(fitPosterior(6, simulate(close, 20, 7), empirical).priorVariance, 1.0) << "never below the floor";
    EXPECT_EQ(fitPosterior(6, {}, empirical).priorVariance, 1.0) << "no answers: the prior as given";
    PosteriorOptions capped = empirical;
    capped.maxPriorVariance = 2.0;
    EXPECT_EQ(fitPosterior(6, simulate(wide, 20, 7), capped).priorVariance, 2.0) << "never above the cap";
}

TEST(ActiveSampling, PosteriorDependsOnlyOnTheAnswersNotTheirOrder) {
    const std::vector<double> truth = {0.0, 0.4, 1.0, 2.2, -0.7};
    std::vector<Comparison> answers = simulate(truth, 7, 3);
    const ScorePosterior a = fitPosterior(5, answers);
    std::mt19937_64 random(9);
    std::shuffle(answers.begin(), answers.end(), random);
    const ScorePosterior b = fitPosterior(5, answers);
    const ScorePosterior c = fitPosterior(5, answers); // rebuilt again (a restart)
    for (std::size_t i = 0; i < 5; ++i) {
        EXPECT_EQ(a.mean[i], b.mean[i]);
        EXPECT_EQ(b.mean[i], c.mean[i]);
    }
    EXPECT_EQ(a.covariance, b.covariance);
    EXPECT_EQ(b.covariance, c.covariance);
    EXPECT_EQ(spanningTreeBatch(a, 77), spanningTreeBatch(c, 77));
    // Before any answer: the prior.
    const ScorePosterior prior = fitPosterior(3, {});
    EXPECT_EQ(prior.mean, std::vector<double>(3, 0.0));
    EXPECT_EQ(
        prior.covariance,
        ScorePosterior::independent({0, 0, 0}, std::vector<double>(3, PosteriorOptions{}.priorVariance)).covariance);
    EXPECT_THROW(fitPosterior(3, {{0, 3}}), skinlab::RuntimeError);
    // The same answers as counts per pair (how the server keeps them in memory): the identical posterior.
    std::map<std::pair<int, int>, std::pair<double, double>> counted;
    for (const Comparison& x : answers) {
        auto& entry = counted[{std::min(x.winner, x.loser), std::max(x.winner, x.loser)}];
        (x.winner < x.loser ? entry.first : entry.second) += 1.0;
    }
    std::vector<PairCount> counts;
    for (const auto& [pair, won] : counted) counts.push_back({pair.first, pair.second, won.first, won.second});
    const ScorePosterior d = fitPosteriorFromCounts(5, counts);
    EXPECT_EQ(d.mean, a.mean);
    EXPECT_EQ(d.covariance, a.covariance);
    EXPECT_EQ(d.comparisons, static_cast<int>(answers.size()));
    std::vector<PairCount> unsorted = counts;
    std::swap(unsorted[0], unsorted[1]);
    EXPECT_THROW(fitPosteriorFromCounts(5, unsorted), skinlab::RuntimeError);
    EXPECT_THROW(fitPosteriorFromCounts(5, {{0, 1, 0.0, 0.0}}), skinlab::RuntimeError);
}

TEST(ActiveSampling, GreedyBatchSpreadsItsPairs) {
    // Without an update a greedy batch would repeat the single best pair; with the covariance update for the pairs
    // already chosen it moves on, and it is reproducible from its seed.
    const std::vector<double> truth = {0.0, 0.1, 0.2, 2.0, 4.0, 6.0};
    const ScorePosterior p = fitPosterior(6, simulate(truth, 3, 5));
    const auto batch = greedyBatch(p, 5, 3);
    ASSERT_EQ(batch.size(), 5u);
    std::set<std::pair<int, int>> unique(batch.begin(), batch.end());
    EXPECT_GE(unique.size(), 3u);
    for (const auto& [a, b] : batch) EXPECT_LT(a, b);
    EXPECT_EQ(batch, greedyBatch(p, 5, 3));
    EXPECT_TRUE(greedyBatch(fitPosterior(1, {}), 3, 1).empty());
}

TEST(ActiveSampling, SequentialTreeBatchIsASpanningTree) {
    // The tree grown edge by edge (each edge valued under the covariance the earlier edges' answers will leave):
    // m − 1 pairs that connect every condition, reproducible from its seed.
    const std::vector<double> truth = {0.0, 0.1, 0.2, 2.0, 4.0, 6.0};
    const ScorePosterior p = fitPosterior(6, simulate(truth, 3, 5));
    const auto tree = sequentialTreeBatch(p, 3);
    ASSERT_EQ(tree.size(), 5u);
    std::vector<int> component = {0, 1, 2, 3, 4, 5};
    auto root = [&](int x) {
        while (component[static_cast<std::size_t>(x)] != x) x = component[static_cast<std::size_t>(x)];
        return x;
    };
    for (const auto& [a, b] : tree) {
        EXPECT_LT(a, b);
        EXPECT_NE(root(a), root(b)) << "no cycle";
        component[static_cast<std::size_t>(root(a))] = root(b);
    }
    for (int c = 1; c < 6; ++c) EXPECT_EQ(root(c), root(0)) << "connected";
    EXPECT_EQ(tree, sequentialTreeBatch(p, 3));
    EXPECT_TRUE(sequentialTreeBatch(fitPosterior(1, {}), 1).empty());
}

TEST(ActiveSampling, GainIsHighestForCloseUncertainPairs) {
    const ScorePosterior p = ScorePosterior::independent({0.0, 0.2, 3.0, 0.2}, {1.0, 1.0, 1.0, 0.01});
    // Close beats far at equal uncertainty.
    EXPECT_GT(expectedInformationGain(p, 0, 1), expectedInformationGain(p, 0, 2));
    // Uncertain beats certain at equal distance.
    EXPECT_GT(expectedInformationGain(p, 0, 1), expectedInformationGain(p, 0, 3));
    // Symmetric and positive.
    EXPECT_NEAR(expectedInformationGain(p, 0, 1), expectedInformationGain(p, 1, 0), 1e-12);
    EXPECT_GT(expectedInformationGain(p, 0, 2), 0.0);
    // What counts is the uncertainty of the difference: two scores known only together (strongly correlated) make
    // a pair with little to teach, although each score alone is uncertain.
    ScorePosterior correlated = ScorePosterior::independent({0.0, 0.1, 0.0}, {1.0, 1.0, 1.0});
    correlated.covariance[1] = correlated.covariance[3] = 0.95; // cov(0, 1)
    EXPECT_LT(expectedInformationGain(correlated, 0, 1), 0.2 * expectedInformationGain(correlated, 0, 2));
    // A chain of answers 0–1–2–…–5 ties neighbours closer than the chain's ends: the ends' difference is the most
    // uncertain, so at equal estimated distance the gain prefers the shortcut.
    std::vector<Comparison> chain;
    for (int r = 0; r < 10; ++r)
        for (int i = 0; i < 5; ++i) {
            chain.push_back({i, i + 1});
            chain.push_back({i + 1, i});
        }
    const ScorePosterior chained = fitPosterior(6, chain);
    EXPECT_GT(chained.cov(0, 0) + chained.cov(5, 5) - 2 * chained.cov(0, 5),
              2 * (chained.cov(0, 0) + chained.cov(1, 1) - 2 * chained.cov(0, 1)));
    EXPECT_GT(expectedInformationGain(chained, 0, 5), expectedInformationGain(chained, 0, 1));
    // After data: a close pair teaches more than a far one.
    const ScorePosterior fitted = fitPosterior(5, simulate({-2.0, 0.0, 0.1, 2.0, 4.0}, 6, 1));
    const auto gains = informationGains(fitted);
    EXPECT_GT(gains[1][2], gains[0][4]);
    EXPECT_GT(gains[1][2], gains[1][4]);
    std::pair<int, int> best{0, 1};
    for (int i = 0; i < 5; ++i)
        for (int j = i + 1; j < 5; ++j)
            if (gains[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] >
                gains[static_cast<std::size_t>(best.first)][static_cast<std::size_t>(best.second)])
                best = {i, j};
    // A minimum spanning tree always holds the lightest edge (the highest gain) — first, as batches are sorted.
    EXPECT_EQ(spanningTreeBatch(fitted, 5, BatchCriterion::informationGain).front(), best);
}

TEST(ActiveSampling, VarianceReductionFavoursPairsThatShrinkTheScalesUncertainty) {
    // Equal means: the pair whose difference is uncertain reduces the summed variance of the centred scores more
    // than the pair already pinned down (strongly correlated scores), and an answer to a near-unanimous pair
    // teaches little.
    ScorePosterior p = ScorePosterior::independent({0.0, 0.0, 0.0, 6.0}, {1.0, 1.0, 1.0, 1.0});
    p.covariance[0 * 4 + 1] = p.covariance[1 * 4 + 0] = 0.95;
    const auto values = pairValues(p, BatchCriterion::varianceReduction);
    EXPECT_GT(values[0][2], 3.0 * values[0][1]);
    EXPECT_GT(values[0][2], values[2][3]);
    for (int i = 0; i < 4; ++i) {
        EXPECT_EQ(values[static_cast<std::size_t>(i)][static_cast<std::size_t>(i)], 0.0);
        for (int j = 0; j < 4; ++j)
            EXPECT_EQ(values[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)],
                      values[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)]);
    }
    // The same reduction as the greedy batch's first choice (both evaluate π/(1 + π v) ‖C Σ a‖²).
    const auto greedy = greedyBatch(p, 1, 3, BatchCriterion::varianceReduction);
    ASSERT_EQ(greedy.size(), 1u);
    double best = 0.0;
    for (const auto& row : values)
        for (const double v : row) best = std::max(best, v);
    EXPECT_NEAR(values[static_cast<std::size_t>(greedy[0].first)][static_cast<std::size_t>(greedy[0].second)], best,
                1e-12);
    // Against the exact update: one answer's expected precision on d applied as a rank-one update of Σ reduces
    // the trace of C Σ C by the value.
    const int i = 0, j = 2;
    const double vd = p.cov(i, i) + p.cov(j, j) - 2 * p.cov(i, j);
    std::vector<double> sa(4);
    for (int r = 0; r < 4; ++r) sa[static_cast<std::size_t>(r)] = p.cov(r, i) - p.cov(r, j);
    auto centredTrace = [](const std::vector<double>& c) {
        double trace = 0.0, total = 0.0;
        for (int r = 0; r < 4; ++r) trace += c[static_cast<std::size_t>(r * 4 + r)];
        for (const double x : c) total += x;
        return trace - total / 4.0;
    };
    // The value is gain·‖CΣa‖² with gain = π/(1 + π v); recover π from it and check that the rank-one update with
    // that π reduces the centred trace by exactly the value, and that π is positive and below 1/σ² (one answer).
    double norm = 0.0, meanSa = 0.0;
    for (const double x : sa) meanSa += x / 4.0;
    for (const double x : sa) norm += (x - meanSa) * (x - meanSa);
    const double gain = values[0][2] / norm;
    const double precision = gain / (1.0 - gain * vd);
    EXPECT_GT(precision, 0.0);
    EXPECT_LT(precision, 1.0 / (kThurstoneSigma * kThurstoneSigma));
    std::vector<double> after = p.covariance;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c)
            after[static_cast<std::size_t>(r * 4 + c)] -=
                gain * sa[static_cast<std::size_t>(r)] * sa[static_cast<std::size_t>(c)];
    EXPECT_NEAR(centredTrace(p.covariance) - centredTrace(after), values[0][2], 1e-12);
}

TEST(ActiveSampling, BatchIsAConnectedSpanningTreeReproducibleFromItsSeed) {
    for (const int m : {2, 3, 10, 30}) {
        std::vector<double> truth;
        for (int i = 0; i < m; ++i) truth.push_back(0.2 * i);
        for (const bool withData : {false, true}) {
            const ScorePosterior p = fitPosterior(m, withData ? simulate(truth, 2, 4) : std::vector<Comparison>{});
            for (const BatchCriterion criterion :
                 {BatchCriterion::informationGain, BatchCriterion::varianceReduction}) {
                const auto tree = spanningTreeBatch(p, 11, criterion);
                ASSERT_EQ(tree.size(), static_cast<std::size_t>(m - 1)) << m;
                EXPECT_TRUE(connected(m, tree)) << m;
            }
            const auto batch = spanningTreeBatch(p, 11);
            ASSERT_EQ(batch.size(), static_cast<std::size_t>(m - 1)) << m;
            EXPECT_TRUE(connected(m, batch)) << m;
            std::set<std::pair<int, int>> unique(batch.begin(), batch.end());
            EXPECT_EQ(unique.size(), batch.size());
            for (const auto& [a, b] : batch) EXPECT_LT(a, b);
            EXPECT_EQ(batch, spanningTreeBatch(p, 11));
        }
    }
    // Before any answer every gain is equal: the seed picks the tree, so participants starting together differ.
    const ScorePosterior prior = fitPosterior(12, {});
    EXPECT_NE(spanningTreeBatch(prior, 1), spanningTreeBatch(prior, 2));
    EXPECT_TRUE(spanningTreeBatch(fitPosterior(1, {}), 1).empty());
}

TEST(ActiveSampling, WithPriorReplacesOnlyThePriorsPrecision) {
    // No answers: the posterior is the prior, so another prior is exactly that prior.
    const ScorePosterior none = withPrior(fitPosterior(3, {}), 4.0);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) EXPECT_NEAR(none.cov(i, j), i == j ? 4.0 : 0.0, 1e-12);
    // With answers: there and back again, and a wider prior leaves far-apart differences less certain.
    std::vector<Comparison> answers;
    for (int k = 0; k < 15; ++k) answers.push_back({0, 1}), answers.push_back({1, 2}), answers.push_back({2, 3});
    const ScorePosterior fitted = fitPosterior(4, answers);
    const ScorePosterior wide = withPrior(fitted, 100.0);
    const ScorePosterior back = withPrior(wide, fitted.priorVariance);
    for (int i = 0; i < 4; ++i) {
        EXPECT_EQ(wide.mean[static_cast<std::size_t>(i)], fitted.mean[static_cast<std::size_t>(i)]);
        for (int j = 0; j < 4; ++j) EXPECT_NEAR(back.cov(i, j), fitted.cov(i, j), 1e-9);
    }
    auto differenceVariance = [](const ScorePosterior& p, int i, int j) {
        return p.cov(i, i) + p.cov(j, j) - 2.0 * p.cov(i, j);
    };
    EXPECT_GT(differenceVariance(wide, 0, 3), 1.5 * differenceVariance(fitted, 0, 3));
    EXPECT_THROW(withPrior(fitted, 0.0), skinlab::RuntimeError);
}

TEST(ActiveSampling, DesignKeysAreCheckedStrictly) {
    const StudyDesign d = parseStudyDesign("pairs = \"active\"\ntrials_per_participant = 30\n", "D.toml");
    EXPECT_TRUE(d.activePairs);
    EXPECT_TRUE(d.allPairs);
    EXPECT_EQ(d.trialsPerParticipant, 30);
    const StudyDesign back = StudyDesign::fromJson(d.toJson());
    EXPECT_TRUE(back.activePairs);
    EXPECT_EQ(back.trialsPerParticipant, 30);
    EXPECT_FALSE(StudyDesign::fromJson(parseStudyDesign("", "D.toml").toJson()).activePairs);

    EXPECT_EQ(designError("pairs = \"active\"\n"),
              "D.toml: trials_per_participant: required with pairs = \"active\" (test trials per participant)");
    EXPECT_EQ(designError("pairs = \"active\"\ntrials_per_participant = 0\n"),
              "D.toml: trials_per_participant: 0 is out of range [1, 10000]");
    EXPECT_EQ(designError("pairs = \"active\"\ntrials_per_participant = 10\nrepetitions = 2\n"),
              "D.toml: repetitions: not used with pairs = \"active\" (the planner chooses every test trial; set "
              "trials_per_participant)");
    EXPECT_EQ(designError("pairs = \"active\"\ntrials_per_participant = 10\nblock_order = \"grouped\"\n"),
              "D.toml: block_order: not used with pairs = \"active\" (each batch is planned for one block)");
    EXPECT_EQ(designError("trials_per_participant = 10\n"),
              "D.toml: trials_per_participant: only used with pairs = \"active\"");
    EXPECT_EQ(designError("active_batch = 2\n"), "D.toml: active_batch: only used with pairs = \"active\"");
    EXPECT_EQ(designError("pairs = \"active\"\ntrials_per_participant = 10\nactive_batch = -1\n"),
              "D.toml: active_batch: -1 is out of range [0, 10000]");
    const StudyDesign small =
        parseStudyDesign("pairs = \"active\"\ntrials_per_participant = 30\nactive_batch = 1\n", "D.toml");
    EXPECT_EQ(small.activeBatch, 1);
    EXPECT_EQ(StudyDesign::fromJson(small.toJson()).activeBatch, 1);
    EXPECT_FALSE(d.toJson().contains("active_batch")) << "unset: the stored design is as it was";
    // active_prior_sd: the planner's prior, stored only where set; the posterior options follow it.
    EXPECT_EQ(d.activePriorSd, 1.0);
    EXPECT_FALSE(d.toJson().contains("active_prior_sd"));
    EXPECT_EQ(plannerPosteriorOptions(d).priorVariance, 1.0);
    const StudyDesign wide =
        parseStudyDesign("pairs = \"active\"\ntrials_per_participant = 30\nactive_prior_sd = 2.0\n", "D.toml");
    EXPECT_EQ(wide.activePriorSd, 2.0);
    EXPECT_EQ(StudyDesign::fromJson(wide.toJson()).activePriorSd, 2.0);
    EXPECT_EQ(plannerPosteriorOptions(wide).priorVariance, 4.0);
    EXPECT_EQ(designError("active_prior_sd = 2.0\n"), "D.toml: active_prior_sd: only used with pairs = \"active\"");
    EXPECT_EQ(designError("pairs = \"active\"\ntrials_per_participant = 10\nactive_prior_sd = 0.1\n"),
              "D.toml: active_prior_sd: 0.1 is out of range [0.25, 10]");
    EXPECT_EQ(designError("pairs = \"activ\"\n"),
              "D.toml: pairs: expected \"all\", \"active\" or an array of [A, B] condition pairs, got \"activ\"");
}

TEST(ActiveSampling, PlanFillsOpenSlotsBatchByBatchAroundPracticeAndCatchTrials) {
    const StudyDefinition study = makeStudy(
        "seed = 3\npairs = \"active\"\ntrials_per_participant = 10\n[practice]\ntrials = 2\n[catch]\nblank = 2\n");
    ASSERT_EQ(study.blocks.size(), 2u);
    ASSERT_EQ(study.blocks[0].conditions.size(), 4u); // batches of 3 pairs
    EXPECT_EQ(study.testTrialCount(), 10);
    EXPECT_EQ(study.repeatTrialCount(), 0);
    const std::uint64_t seed = participantSeed(study.design.seed, 1);
    const std::vector<PlannedTrial> skeleton = planTrials(study, 1, seed);
    ASSERT_EQ(skeleton.size(), 14u);
    EXPECT_EQ(std::count_if(skeleton.begin(), skeleton.end(), isActiveSlot), 10);

    int posteriorCalls = 0;
    auto prior = [&](std::size_t b) {
        ++posteriorCalls;
        return fitPosterior(static_cast<int>(study.blocks[b].conditions.size()), {});
    };
    std::vector<PlannedTrial> stored;
    std::vector<std::size_t> stretches;
    for (int guard = 0; guard < 20; ++guard) {
        const std::vector<PlannedTrial> next = nextActiveTrials(study, 1, seed, stored, prior);
        if (next.empty()) break;
        stretches.push_back(next.size());
        stored.insert(stored.end(), next.begin(), next.end());
    }
    ASSERT_EQ(stored.size(), skeleton.size());
    EXPECT_EQ(posteriorCalls, 4) << "10 test trials in batches of 3: 3 + 3 + 3 + 1";
    std::map<std::string, int> perBlock;
    int left = 0;
    for (std::size_t k = 0; k < stored.size(); ++k) {
        EXPECT_FALSE(isActiveSlot(stored[k]));
        EXPECT_EQ(stored[k].kind, skeleton[k].kind) << k;
        if (skeleton[k].kind != TrialKind::test) {
            EXPECT_EQ(stored[k].conditionA, skeleton[k].conditionA) << "practice/catch trial " << k << " kept";
            EXPECT_EQ(stored[k].stimulusB, skeleton[k].stimulusB);
        } else {
            ++perBlock[stored[k].block];
            left += stored[k].aOnLeft ? 1 : 0;
            EXPECT_NE(stored[k].conditionA, stored[k].conditionB);
        }
        if (k > 0 && stored[k].kind == TrialKind::test && stored[k - 1].kind == TrialKind::test) {
            EXPECT_FALSE(stored[k].block == stored[k - 1].block && stored[k].conditionA == stored[k - 1].conditionA &&
                         stored[k].conditionB == stored[k - 1].conditionB);
        }
    }
    EXPECT_EQ(left, 5) << "A on the left in exactly half of the test trials";
    EXPECT_EQ(perBlock.size(), 2u) << "batches alternate between the blocks";
    // Reproducible: the same answers (here none) give the same plan.
    std::vector<PlannedTrial> again;
    for (std::size_t s : stretches) {
        const auto next = nextActiveTrials(study, 1, seed, again, prior);
        ASSERT_EQ(next.size(), s);
        again.insert(again.end(), next.begin(), next.end());
    }
    for (std::size_t k = 0; k < stored.size(); ++k) {
        EXPECT_EQ(again[k].conditionA, stored[k].conditionA);
        EXPECT_EQ(again[k].aOnLeft, stored[k].aOnLeft);
    }
}

TEST(ActiveSampling, ActiveBatchReplansAfterEveryKTestTrials) {
    const StudyDefinition study = makeStudy("seed = 3\npairs = \"active\"\ntrials_per_participant = 10\n"
                                            "active_batch = 1\n[practice]\ntrials = 2\n[catch]\nblank = 2\n");
    const std::uint64_t seed = participantSeed(study.design.seed, 1);
    const std::vector<PlannedTrial> skeleton = planTrials(study, 1, seed);
    int posteriorCalls = 0;
    auto prior = [&](std::size_t b) {
        ++posteriorCalls;
        return fitPosterior(static_cast<int>(study.blocks[b].conditions.size()), {});
    };
    std::vector<PlannedTrial> stored;
    for (int guard = 0; guard < 40; ++guard) {
        const std::vector<PlannedTrial> next = nextActiveTrials(study, 1, seed, stored, prior);
        if (next.empty()) break;
        EXPECT_EQ(
            std::count_if(next.begin(), next.end(), [](const PlannedTrial& t) { return t.kind == TrialKind::test; }), 1)
            << "one test trial per stretch";
        stored.insert(stored.end(), next.begin(), next.end());
    }
    ASSERT_EQ(stored.size(), skeleton.size());
    EXPECT_EQ(posteriorCalls, 10) << "a posterior per test trial";
    // The trial planned is the most valuable pair of the posterior at that moment: with answers that make two
    // conditions close and uncertain, the planner compares exactly them.
    std::vector<Comparison> answers;
    for (int k = 0; k < 20; ++k) answers.push_back({0, 2}), answers.push_back({1, 3}), answers.push_back({0, 3});
    answers.push_back({2, 1});
    const ScorePosterior informed = fitPosterior(4, answers);
    const auto tree = spanningTreeBatch(informed, combineSeed(seed, 2));
    const std::vector<PlannedTrial> first =
        nextActiveTrials(study, 1, seed, {stored.begin(), stored.begin() + 2}, [&](std::size_t) { return informed; });
    ASSERT_FALSE(first.empty());
    const auto test =
        *std::find_if(first.begin(), first.end(), [](const PlannedTrial& t) { return t.kind == TrialKind::test; });
    const auto block = std::find_if(study.blocks.begin(), study.blocks.end(),
                                    [&](const StudyBlock& b) { return b.name == test.block; });
    ASSERT_NE(block, study.blocks.end());
    const auto& conditions = block->conditions;
    const std::pair<std::string, std::string> best = {conditions[static_cast<std::size_t>(tree.front().first)],
                                                      conditions[static_cast<std::size_t>(tree.front().second)]};
    EXPECT_TRUE((test.conditionA == best.first && test.conditionB == best.second) ||
                (test.conditionA == best.second && test.conditionB == best.first));
}
