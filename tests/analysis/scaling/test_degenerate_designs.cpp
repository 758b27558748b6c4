// Data that real studies produce and that break a studentized bootstrap: observers who all answer alike,
// unanimous pairs, resamples whose spread is zero, disconnected designs, two-condition blocks with lopsided
// counts. Every case must finish (ctest TIMEOUT), write its outputs, and give finite, honest intervals and
// p-values that agree with the exact binomial test where there is one.
#include "analysis/scaling/comparison_data.h"
#include "analysis/scaling/plots.h"
#include "analysis/scaling/scale_analysis.h"
#include "analysis/scaling/scale_report.h"
#include "analysis/scaling/simulation.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace skinlab::analysis::scaling {
namespace {

namespace fs = std::filesystem;

// One observer's answers to one pair: `first` times condition a chosen over b, `second` times b over a.
struct Answers {
    int a = 0, b = 0, first = 0, second = 0;
};

// A single-block dataset from per-observer answers (observer k answers `answers[k]`).
Dataset dataset(int conditions, const std::vector<std::vector<Answers>>& answers) {
    ResponseTable table;
    table.file = "synthetic.csv";
    table.format = ResponseFormat::PwcmpCsv;
    int line = 2;
    for (size_t k = 0; k < answers.size(); ++k)
        for (const Answers& pair : answers[k])
            for (int r = 0; r < pair.first + pair.second; ++r) {
                Response response;
                response.observer = "o" + std::to_string(k);
                response.block = "block";
                response.conditionA = "c" + std::to_string(pair.a);
                response.conditionB = "c" + std::to_string(pair.b);
                response.aSelected = r < pair.first;
                response.line = line++;
                table.responses.push_back(response);
            }
    DatasetOptions options;
    for (int i = 0; i < conditions; ++i) options.conditionOrder.push_back("c" + std::to_string(i));
    return buildDataset(table, options);
}

AnalysisOptions quickOptions() {
    AnalysisOptions options;
    options.bootstrap.samples = 400;
    options.bootstrap.threads = 1;
    return options;
}

fs::path scratch(const std::string& name) {
    const fs::path folder = fs::path(SKINLAB_BINARY_DIR) / "test-scratch" / "scaling-degenerate" / name;
    fs::remove_all(folder);
    return folder;
}

// Every end of an interval that the data set (bound "two-sided", or the one end of "lower"/"upper") is finite,
// on the right side of its estimate and at most `maximumHalfWidth` JOD from it; an end the data do not set
// (unanimous answers, disconnected designs) is infinite instead of a value chosen by the prior; intervals with both
// ends have a positive width.
void expectHonestIntervals(const BlockAnalysis& block, double maximumHalfWidth) {
    auto expectEnds = [&](double low, double high, double estimate, const std::string& bound, const std::string& what) {
        const bool lowSet = bound == "two-sided" || bound == "lower";
        const bool highSet = bound == "two-sided" || bound == "upper";
        ASSERT_TRUE(bound == "two-sided" || bound == "lower" || bound == "upper" || bound == "none") << what;
        EXPECT_EQ(std::isfinite(low), lowSet) << what << " " << bound << " low " << low;
        EXPECT_EQ(std::isfinite(high), highSet) << what << " " << bound << " high " << high;
        EXPECT_TRUE(std::isnan(low) == false && std::isnan(high) == false) << what;
        EXPECT_LE(low, estimate) << what;
        EXPECT_GE(high, estimate) << what;
        if (lowSet) {
            EXPECT_LE(estimate - low, maximumHalfWidth) << what;
        }
        if (highSet) {
            EXPECT_LE(high - estimate, maximumHalfWidth) << what;
        }
        if (lowSet && highSet) {
            EXPECT_GT(high - low, 0.05) << what << ": a zero-width interval";
        }
    };
    for (size_t i = 0; i < block.conditions.size(); ++i) {
        const auto k = static_cast<Eigen::Index>(i);
        expectEnds(block.low[k], block.high[k], block.thurstone.scores[k], block.intervalFlags[i].bound,
                   block.conditions[i]);
    }
    for (const PairTest& pair : block.pairs) {
        const std::string what = block.conditions[pair.test.first] + " - " + block.conditions[pair.test.second];
        expectEnds(pair.test.low, pair.test.high, pair.test.difference, pair.test.diagnosis.bound, what);
        EXPECT_TRUE(std::isfinite(pair.test.pValue)) << what;
        const auto& reasons = pair.test.diagnosis.reasons;
        if (std::find(reasons.begin(), reasons.end(), "disconnected") != reasons.end()) {
            // Never compared, not even indirectly: not measured, and no test.
            EXPECT_EQ(pair.test.diagnosis.bound, "none") << what;
            EXPECT_EQ(pair.test.pValue, 1.0) << what;
            EXPECT_FALSE(pair.significant) << what;
        }
    }
}

// 4 conditions, 5 observers, every observer answers every pair twice and all answer the same way.
std::vector<std::vector<Answers>> identicalObservers() {
    const std::vector<Answers> one = {{0, 1, 0, 2}, {0, 2, 0, 2}, {0, 3, 0, 2},
                                      {1, 2, 0, 2}, {1, 3, 0, 2}, {2, 3, 0, 2}};
    return std::vector<std::vector<Answers>>(5, one);
}

TEST(DegenerateDesigns, IdenticalUnanimousObserversFinishAndWriteScaleJson) {
    const Dataset data = dataset(4, identicalObservers());
    const Analysis analysis = analyzeDataset(data, quickOptions());
    const fs::path folder = scratch("identical");
    writeScaleOutputs(analysis, folder); // hung in the score plot (one grid line per JOD up to ±1e9)
    ASSERT_TRUE(fs::exists(folder / "scale.json"));
    const BlockAnalysis& block = analysis.blocks.at(0);
    expectHonestIntervals(block, 60.0);
    std::ifstream stream(folder / "scale.json");
    const nlohmann::json json = nlohmann::json::parse(stream);
    for (const auto& score : json["blocks"][0]["scores"]) {
        EXPECT_EQ(score["interval_method"], "percentile+profile") << score.dump();
        EXPECT_FALSE(score["fallback_reasons"].empty()) << score.dump();
    }
}

TEST(DegenerateDesigns, UnanimousStudiesGetOneSidedBoundsInsteadOfPriorSetEnds) {
    // 5 observers, 4 conditions, every answer unanimous (c3 ≻ c2 ≻ c1 ≻ c0). The interval of c3 used to be
    // [3.15, 20.11]: its upper end was the prior's. The data say "at least" for the best condition, "at most" for
    // the worst, and nothing about the middle ones relative to the mean.
    const Analysis analysis = analyzeDataset(dataset(4, identicalObservers()), quickOptions());
    const BlockAnalysis& block = analysis.blocks.at(0);
    EXPECT_EQ(block.intervalFlags[3].bound, "lower");
    EXPECT_GT(block.low[3], 0.0);
    EXPECT_TRUE(std::isinf(block.high[3]));
    EXPECT_EQ(block.intervalFlags[0].bound, "upper");
    EXPECT_LT(block.high[0], 0.0);
    EXPECT_EQ(block.intervalFlags[1].bound, "none");
    EXPECT_EQ(block.intervalFlags[2].bound, "none");
    for (const PairTest& pair : block.pairs) {
        // first < second and the second always won: q_first − q_second is at most a negative number.
        EXPECT_EQ(pair.test.diagnosis.bound, "upper") << pair.test.first << "," << pair.test.second;
        EXPECT_LT(pair.test.high, 0.0) << pair.test.first << "," << pair.test.second;
    }
    const fs::path folder = scratch("unanimous-bounds");
    writeScaleOutputs(analysis, folder);
    std::ifstream stream(folder / "scale.json");
    const nlohmann::json json = nlohmann::json::parse(stream);
    const auto& best = json["blocks"][0]["scores"][3];
    EXPECT_EQ(best["bound"], "lower");
    EXPECT_TRUE(best["ci_high"].is_null());
    EXPECT_GT(best["ci_low"].get<double>(), 0.0);
    EXPECT_EQ(json["settings"]["prior"], "gaussian");
}

TEST(DegenerateDesigns, AUnanimousPairsFiniteEndIsTheExactOneSidedBound) {
    // 10 observers each chose c1 over c0 once: 10:0. The data bound c1 − c0 from below only. An exact
    // (Clopper–Pearson) bound at 97.5 % is P ≥ 0.025^(1/10) = 0.6915, d ≥ 1.4826·Φ⁻¹(0.6915) = 0.742 JOD; a true
    // difference of 1.0 JOD (P = 0.75) gives 10:0 in 5.6 % of studies, so a bound above it would miss that often.
    // The χ²₁ profile bound sat at P ≥ 0.825 (1.38 JOD), above the true 1.0 of studies that answer 10:0.
    std::vector<std::vector<Answers>> answers(10, std::vector<Answers>{{0, 1, 0, 1}});
    const Analysis analysis = analyzeDataset(dataset(2, answers), quickOptions());
    const BlockAnalysis& block = analysis.blocks.at(0);
    const PairTest& pair = block.pairs.at(0);
    EXPECT_EQ(pair.test.diagnosis.bound, "upper"); // q0 − q1 is at most a negative number
    EXPECT_TRUE(pair.test.diagnosis.priorDriven);
    EXPECT_TRUE(std::isinf(pair.test.low));
    EXPECT_NEAR(pair.test.high, -0.742, 0.03);
    EXPECT_EQ(block.intervalFlags[1].bound, "lower");
    EXPECT_TRUE(block.intervalFlags[1].priorDriven);
    EXPECT_NEAR(block.low[1], 0.371, 0.02); // half the difference: the score relative to the mean of two
}

TEST(DegenerateDesigns, DisconnectedComponentsAreScaledSeparately) {
    // A count matrix (profile intervals) with two components of three conditions: each score used to get ±7.3 JOD
    // (the prior's spread between the components). Each component is centred on its own mean, its scores get
    // data-sized intervals, and differences across components are not measured.
    for (const Prior prior : {Prior::Gaussian, Prior::Pwcmp}) {
        ResponseTable table;
        table.file = "disconnected.csv";
        table.format = ResponseFormat::CountMatrix;
        table.matrixConditions = {"a", "b", "c", "d", "e", "f"};
        table.matrixCounts.assign(36, 0.0);
        auto set = [&](int i, int j, double wins, double losses) {
            table.matrixCounts[i * 6 + j] = wins;
            table.matrixCounts[j * 6 + i] = losses;
        };
        set(1, 0, 14, 6), set(2, 1, 13, 7), set(2, 0, 17, 3); // a < b < c
        set(4, 3, 15, 5), set(5, 4, 12, 8), set(5, 3, 16, 4); // d < e < f
        AnalysisOptions options = quickOptions();
        options.fit.prior = prior;
        const Analysis analysis = analyzeDataset(buildDataset(table, {}), options);
        const BlockAnalysis& block = analysis.blocks.at(0);
        ASSERT_EQ(block.components.size(), 2u);
        EXPECT_EQ(block.intervalMethod, "profile-likelihood");
        expectHonestIntervals(block, 2.5);
        EXPECT_NEAR(block.thurstone.scores.head(3).sum(), 0.0, 1e-6) << priorName(prior);
        EXPECT_NEAR(block.thurstone.scores.tail(3).sum(), 0.0, 1e-6) << priorName(prior);
        for (int i = 0; i < 6; ++i) EXPECT_EQ(block.intervalFlags[i].bound, "two-sided") << i;
        int notMeasured = 0;
        for (const PairTest& pair : block.pairs) notMeasured += pair.test.diagnosis.bound == "none";
        EXPECT_EQ(notMeasured, 9) << priorName(prior);
        bool warned = false;
        for (const std::string& warning : block.warnings)
            warned = warned || warning.find("cannot be compared") != std::string::npos;
        EXPECT_TRUE(warned);
    }
}

TEST(DegenerateDesigns, NineUnanimousPairsOfTwelveObserversFinish) {
    // 5 conditions, 12 observers; nine of the ten pairs unanimous (the higher index always wins), the pair
    // (c1, c2) split 7:5 across observers.
    std::vector<std::vector<Answers>> answers(12);
    for (int k = 0; k < 12; ++k)
        for (int i = 0; i < 5; ++i)
            for (int j = i + 1; j < 5; ++j) {
                if (i == 1 && j == 2) answers[k].push_back({i, j, k < 5 ? 1 : 0, k < 5 ? 0 : 1});
                else answers[k].push_back({i, j, 0, 1});
            }
    const Dataset data = dataset(5, answers);
    const Analysis analysis = analyzeDataset(data, quickOptions());
    const fs::path folder = scratch("nine-unanimous");
    writeScaleOutputs(analysis, folder);
    ASSERT_TRUE(fs::exists(folder / "scale.json"));
    expectHonestIntervals(analysis.blocks.at(0), 60.0);
    // The unanimous pairs carry a data-bounded lower side: the best condition is above the worst.
    const BlockAnalysis& block = analysis.blocks.at(0);
    EXPECT_GT(block.thurstone.scores[4] - block.thurstone.scores[0], 2.0);
}

TEST(DegenerateDesigns, AgreeingObserversDoNotGetZeroWidthIntervals) {
    // All 10 observers answer 3:1, 2:2 and 3:1 on the three pairs: no spread between observers, so the
    // cluster-robust SE is 0, yet 40 binomial trials per pair carry real sampling uncertainty.
    const std::vector<Answers> one = {{0, 1, 1, 3}, {0, 2, 2, 2}, {1, 2, 1, 3}};
    const Dataset data = dataset(3, std::vector<std::vector<Answers>>(10, one));
    const BlockAnalysis block = analyzeBlock(data.blocks.at(0), quickOptions());
    expectHonestIntervals(block, 5.0);
    for (int i = 0; i < 3; ++i) EXPECT_GT(block.high[i] - block.low[i], 0.3) << i;
    for (const auto& flag : block.intervalFlags) EXPECT_TRUE(flag.fallback);
}

// 2 conditions, 10 observers answering twice each: `split` observers answer 1:1, the others 2:0 for c1.
BlockAnalysis twoConditionBlock(int observers, int trials, int split) {
    std::vector<std::vector<Answers>> answers(observers);
    for (int k = 0; k < observers; ++k)
        answers[k].push_back(k < split ? Answers{0, 1, trials / 2, trials - trials / 2} : Answers{0, 1, 0, trials});
    return analyzeBlock(dataset(2, answers).blocks.at(0), quickOptions());
}

TEST(DegenerateDesigns, ResamplesWithoutSpreadKeepIntervalsFinite) {
    // 18:2 from 10 observers: a resample without the two observers who answered 1:1 has se* = 0. With a floor
    // of 1e-9 on se*, |t*| of those resamples reaches ~1e8 and the interval ±3e8 JOD.
    const BlockAnalysis block = twoConditionBlock(10, 2, 2);
    expectHonestIntervals(block, 6.0);
    EXPECT_LT(block.pairs.at(0).test.high, 0.0) << "18:2 separates the two conditions";
}

// Two-sided exact binomial test of k successes in n trials against 1/2.
double exactBinomialP(int k, int n) {
    const int extreme = std::max(k, n - k);
    double tail = 0.0;
    for (int x = extreme; x <= n; ++x)
        tail += std::exp(std::lgamma(n + 1.0) - std::lgamma(x + 1.0) - std::lgamma(n - x + 1.0) - n * std::log(2.0));
    return std::min(1.0, 2.0 * tail);
}

TEST(DegenerateDesigns, TwoConditionPValuesAgreeWithTheExactBinomialTest) {
    struct Case {
        int observers, trials, split, minority;
    };
    // 18:2 and 19:1 (10 observers, 2 trials each), 10:0 (10 observers, 1 trial each), 15:5 (10 × 2).
    for (const Case c : {Case{10, 2, 2, 2}, Case{10, 2, 1, 1}, Case{10, 1, 0, 0}, Case{10, 2, 5, 5}}) {
        const BlockAnalysis block = twoConditionBlock(c.observers, c.trials, c.split);
        const int n = c.observers * c.trials;
        const double exact = exactBinomialP(c.minority, n);
        const double p = block.pairs.at(0).test.pValue;
        SCOPED_TRACE(std::to_string(n - c.minority) + ":" + std::to_string(c.minority));
        // Within a factor of 2 of the exact test (the exact test is discrete and conservative).
        EXPECT_LT(std::abs(std::log10(p) - std::log10(exact)), std::log10(2.0)) << "p = " << p << ", exact " << exact;
    }
}

// A disconnected design: groups {c0, c1, c2} and {c3, c4, c5}, never compared across; 10 observers, each pair
// twice. Per observer, the wins of the first condition of the pairs (c0,c1), (c0,c2), (c1,c2), (c3,c4), (c3,c5),
// (c4,c5), one digit each. Simulated Case V observers (true scores 0, 1, 2 and 0.5, 1.5, 3), no pair unanimous.
std::vector<std::vector<Answers>> disconnectedDesign(const std::vector<std::string>& observers) {
    const std::pair<int, int> pairs[] = {{0, 1}, {0, 2}, {1, 2}, {3, 4}, {3, 5}, {4, 5}};
    std::vector<std::vector<Answers>> answers;
    for (const std::string& digits : observers) {
        answers.emplace_back();
        for (size_t p = 0; p < 6; ++p) {
            const int first = digits[p] - '0';
            answers.back().push_back({pairs[p].first, pairs[p].second, first, 2 - first});
        }
    }
    return answers;
}

TEST(DegenerateDesigns, DisconnectedDesignsGetPercentileSizedIntervals) {
    // The first never finished (the score plot); the second gave c5 [-10.7, 14.0] where the percentile interval
    // is [1.03, 3.69].
    for (const auto& design : {disconnectedDesign({"101000", "010100", "000100", "011010", "001101", "101000", "001000",
                                                   "101101", "001101", "000000"}),
                               disconnectedDesign({"001100", "000000", "111100", "101100", "100111", "000000", "100000",
                                                   "012000", "101100", "200000"})}) {
        const Analysis analysis = analyzeDataset(dataset(6, design), quickOptions());
        writeScaleOutputs(analysis, scratch("disconnected"));
        const BlockAnalysis& block = analysis.blocks.at(0);
        ASSERT_EQ(block.components.size(), 2u);
        ASSERT_TRUE(block.unanimousPairs.empty());
        expectHonestIntervals(block, 4.0);
        for (int i = 0; i < 6; ++i) {
            // Never narrower than pwcmp's percentile interval, and at most ~2.5 times as wide.
            EXPECT_LE(block.low[i], block.percentileLow[i] + 1e-9) << i;
            EXPECT_GE(block.high[i], block.percentileHigh[i] - 1e-9) << i;
            EXPECT_LE(block.high[i] - block.low[i], 2.5 * (block.percentileHigh[i] - block.percentileLow[i]) + 0.5)
                << i;
            EXPECT_TRUE(block.intervalFlags[i].fallback) << i;
        }
    }
}

TEST(DegenerateDesigns, CompleteDesignsKeepTheStudentizedInterval) {
    SimulationDesign design;
    design.trueScores = {0.0, 0.3, 0.9, 1.0, 1.8, 2.5};
    design.observers = 12;
    design.trialsPerPair = 4;
    int fallbacks = 0;
    for (int experiment = 0; experiment < 5; ++experiment) {
        const SimulatedBlock simulated = simulateBlock(design, 500 + experiment);
        const BlockAnalysis block = analyzeBlock(simulated.block, quickOptions());
        for (const auto& flag : block.intervalFlags) fallbacks += flag.fallback;
    }
    EXPECT_EQ(fallbacks, 0);
}

TEST(DegenerateDesigns, ScorePlotDoesNotDependOnTheSizeOfABound) {
    // Bounds of ±1e9 JOD and a NaN: the plot must finish, whatever its content.
    BlockAnalysis block;
    block.name = "huge";
    block.conditions = {"a", "b", "c"};
    block.thurstone.scores = Eigen::Vector3d(-1.0, 0.0, 1.0);
    block.low = Eigen::Vector3d(-1e9, -0.5, std::nan(""));
    block.high = Eigen::Vector3d(1e9, 0.5, 2.0);
    const cv::Mat image = plotScores(block);
    EXPECT_GT(image.rows, 0);
    EXPECT_LT(image.cols, 4000);
}

} // namespace
} // namespace skinlab::analysis::scaling
