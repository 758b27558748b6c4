// Metrics against the JOD scale on synthetic studies with known answers: correlations computed by hand, intervals
// that collapse to the estimate when every observer answered alike, and the share of significant pairs a metric
// orders correctly when the significant pairs are set by hand.
#include "analysis/agreement/metric_agreement.h"

#include "analysis/scaling/comparison_data.h"
#include "analysis/scaling/responses.h"
#include "common/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

namespace skinlab::analysis::agreement {
namespace {
namespace scaling = skinlab::analysis::scaling;

const std::vector<std::string> conditions = {"a", "b", "c", "d"};

// Every observer answers each pair i < j `trials` times, choosing the later condition wins[j − i − 1] times
// (conditions get better in order). `spread` adds ±1 win alternately between observers.
scaling::Dataset dataset(int observers, const std::vector<int>& wins, int trials, int spread) {
    scaling::ResponseTable table;
    table.file = "synthetic";
    for (int o = 0; o < observers; ++o)
        for (int i = 0; i < 4; ++i)
            for (int j = i + 1; j < 4; ++j) {
                int later = wins[static_cast<std::size_t>(j - i - 1)] + (o % 2 ? spread : -spread);
                for (int t = 0; t < trials; ++t) {
                    scaling::Response r;
                    r.observer = "P" + std::to_string(o);
                    r.block = "scene";
                    r.conditionA = conditions[static_cast<std::size_t>(i)];
                    r.conditionB = conditions[static_cast<std::size_t>(j)];
                    r.aSelected = t >= later;
                    table.responses.push_back(r);
                }
            }
    return scaling::buildDataset(table, {});
}

std::vector<ConditionMetrics> metricRows(const std::vector<double>& flip) {
    std::vector<ConditionMetrics> rows;
    for (std::size_t i = 0; i < conditions.size(); ++i) {
        ConditionMetrics row{"scene", conditions[i], "stim-" + conditions[i], {}};
        for (const auto& definition : metricDefinitions()) row.values[definition.key] = NAN;
        row.values["image.flip_mean"] = flip[i];
        rows.push_back(row);
    }
    return rows;
}

const MetricAgreement& rowOf(const AgreementResult& result, const std::string& key) {
    for (const auto& row : result.rows)
        if (row.metric.key == key) return row;
    throw std::runtime_error("no row " + key);
}

TEST(MetricAgreement, CorrelationsByHand) {
    // x = 1..4, y = 1, 2, 3, 5: Sxy = 6.5, Sxx = 5, Syy = 8.75, r = 6.5 / sqrt(43.75) = 0.98271; Spearman 1.
    EXPECT_NEAR(pearsonCorrelation({1, 2, 3, 4}, {1, 2, 3, 5}), 6.5 / std::sqrt(43.75), 1e-12);
    EXPECT_DOUBLE_EQ(spearmanCorrelation({1, 2, 3, 4}, {1, 2, 3, 5}), 1.0);
    EXPECT_DOUBLE_EQ(spearmanCorrelation({4, 3, 2, 1}, {1, 2, 3, 50}), -1.0);
    // Ties share their mean rank: x ranks (1.5, 1.5, 3, 4), y ranks (1, 2, 3, 4): r = 4.5 / sqrt(4.5 · 5).
    EXPECT_NEAR(spearmanCorrelation({7, 7, 8, 9}, {1, 2, 3, 4}), 4.5 / std::sqrt(4.5 * 5.0), 1e-12);
    EXPECT_TRUE(std::isnan(pearsonCorrelation({1, 1, 1}, {1, 2, 3})));
    EXPECT_TRUE(std::isnan(pearsonCorrelation({1, 2}, {1, 2})));
}

// Every observer answered alike: each bootstrap resample has the same counts (weights sum to the observer
// count), so the observers add nothing, and the interval is Fisher's z interval over the 4 conditions alone.
TEST(MetricAgreement, IdenticalObserversLeaveTheConditionsInterval) {
    scaling::Dataset data = dataset(6, {15, 18, 19}, 20, 0);
    scaling::AnalysisOptions options;
    options.bootstrap.samples = 100;
    scaling::Analysis analysis = scaling::analyzeDataset(data, options);
    AgreementOptions agreementOptions;
    agreementOptions.samples = 50;
    AgreementResult result =
        computeAgreement(data, analysis, metricRows({0.4, 0.3, 0.2, 0.1}), options.fit, agreementOptions);
    const MetricAgreement& flip = rowOf(result, "image.flip_mean");
    EXPECT_EQ(flip.conditions, 4);
    EXPECT_DOUBLE_EQ(flip.spearman, -1.0);
    std::vector<double> jod(analysis.blocks[0].thurstone.scores.data(), analysis.blocks[0].thurstone.scores.data() + 4);
    EXPECT_NEAR(flip.pearson, pearsonCorrelation({0.4, 0.3, 0.2, 0.1}, jod), 1e-12);
    EXPECT_LT(flip.pearson, -0.95);
    const auto [low, high] = correlationInterval(flip.pearson, 4, false, 0.0, 0.95);
    EXPECT_NEAR(flip.pearsonLow, low, 1e-9);
    EXPECT_NEAR(flip.pearsonHigh, high, 1e-9);
    // Over 4 conditions the interval is ±1.96 in atanh r (its standard error is 1): the old observers-only interval
    // had zero width here.
    EXPECT_NEAR(std::atanh(flip.pearsonHigh) - std::atanh(flip.pearsonLow), 2 * 1.959964, 1e-3);
    EXPECT_LE(flip.pearsonLow, flip.pearson);
    EXPECT_GE(flip.pearsonHigh, flip.pearson);
    EXPECT_EQ(flip.bootstrapSamples, 50);
    // 4 conditions in exact order: 2 of the 24 orderings are as extreme (both directions).
    EXPECT_NEAR(flip.spearmanP, 2.0 / 24.0, 1e-12);
    EXPECT_FALSE(result.warnings.empty()) << "fewer than 8 conditions must be warned about";
    // A metric with no values is undefined, never a number.
    const MetricAgreement& psnr = rowOf(result, "image.psnr_db");
    EXPECT_EQ(psnr.conditions, 0);
    EXPECT_TRUE(std::isnan(psnr.pearson));
    EXPECT_TRUE(std::isnan(psnr.pearsonLow));
    EXPECT_TRUE(std::isnan(psnr.predictedShare));
}

// Observers who differ add their variance: the interval contains the estimate and is wider than the conditions'
// interval alone.
TEST(MetricAgreement, VaryingObserversWidenTheInterval) {
    scaling::Dataset data = dataset(8, {15, 18, 19}, 20, 1);
    scaling::AnalysisOptions options;
    options.bootstrap.samples = 100;
    scaling::Analysis analysis = scaling::analyzeDataset(data, options);
    AgreementOptions agreementOptions;
    agreementOptions.samples = 200;
    AgreementResult result =
        computeAgreement(data, analysis, metricRows({0.4, 0.32, 0.25, 0.1}), options.fit, agreementOptions);
    const MetricAgreement& flip = rowOf(result, "image.flip_mean");
    EXPECT_LE(flip.pearsonLow, flip.pearson);
    EXPECT_GE(flip.pearsonHigh, flip.pearson);
    const auto [low, high] = correlationInterval(flip.pearson, 4, false, 0.0, 0.95);
    EXPECT_GT(flip.pearsonHigh - flip.pearsonLow, high - low + 1e-6);
}

// The exact p of Spearman's ρ = 0.7 over 5 conditions: 28 of the 120 orderings have |ρ| ≥ 0.7 (two-sided 0.233,
// the textbook table's 0.117 one-sided); Pearson's exact p counts the same way. Over 10 conditions Fisher's z.
TEST(MetricAgreement, PValuesOfSmallSamples) {
    EXPECT_NEAR(spearmanCorrelation({1, 2, 3, 4, 5}, {2, 3, 1, 4, 5}), 0.7, 1e-12);
    EXPECT_NEAR(correlationPValue({1, 2, 3, 4, 5}, {2, 3, 1, 4, 5}, true), 28.0 / 120.0, 1e-12);
    EXPECT_NEAR(correlationPValue({1, 2, 3, 4, 5}, {1, 2, 3, 4, 5}, false), 2.0 / 120.0, 1e-12);
    std::vector<double> x(10), y(10);
    for (int i = 0; i < 10; ++i) x[i] = i, y[i] = i + (i % 2 ? 3.0 : -3.0);
    const double r = pearsonCorrelation(x, y);
    EXPECT_NEAR(correlationPValue(x, y, false), std::erfc(std::abs(std::atanh(r)) * std::sqrt(7.0) / std::sqrt(2.0)),
                1e-12);
    EXPECT_TRUE(std::isnan(correlationInterval(0.5, 3, false, 0.0, 0.95).first));
}

// Validation by simulation: conditions drawn at random with metric and true quality correlated ρ (bivariate normal),
// 12 observers answering every pair twice (Thurstone), the scale fitted and the agreement computed as
// `analyze agreement` does. The interval must cover the true ρ in ≥ 94 % of 600 experiments at 5, 10 and 20
// conditions (the old observers-only bootstrap covered far less: it ignores that the conditions are a sample).
TEST(MetricAgreement, IntervalsCoverTheCorrelationAcrossConditions) {
    const double rho = 0.7;
    const char* only = std::getenv("SKINLAB_AGREEMENT_COVERAGE_EXPERIMENTS"); // longer runs by hand
    for (int m : {5, 10, 20}) {
        std::mt19937_64 random(1000 + static_cast<std::uint64_t>(m));
        std::normal_distribution<double> normal;
        int covered = 0, experiments = only ? std::atoi(only) : 600;
        for (int e = 0; e < experiments; ++e) {
            std::vector<double> quality(static_cast<std::size_t>(m)), metric(static_cast<std::size_t>(m));
            std::vector<std::string> names;
            for (int i = 0; i < m; ++i) {
                quality[i] = normal(random);
                metric[i] = rho * quality[i] + std::sqrt(1 - rho * rho) * normal(random);
                names.push_back("c" + std::to_string(i));
            }
            scaling::ResponseTable table;
            table.file = "simulated";
            for (int o = 0; o < 12; ++o)
                for (int i = 0; i < m; ++i)
                    for (int j = i + 1; j < m; ++j)
                        for (int t = 0; t < 2; ++t) {
                            scaling::Response r;
                            r.observer = "P" + std::to_string(o);
                            r.block = "scene";
                            r.conditionA = names[i];
                            r.conditionB = names[j];
                            // Thurstone Case V as the scaling assumes: σ = 1.4826 per JOD difference.
                            r.aSelected = quality[i] - quality[j] + 1.4826 * normal(random) > 0;
                            table.responses.push_back(r);
                        }
            scaling::Dataset data = scaling::buildDataset(table, {});
            scaling::AnalysisOptions options;
            options.bootstrap.samples = 20;
            scaling::Analysis analysis = scaling::analyzeDataset(data, options);
            std::vector<ConditionMetrics> rows;
            for (int i = 0; i < m; ++i) {
                ConditionMetrics row{"scene", names[i], "s" + names[i], {}};
                row.values["image.ssim"] = metric[i];
                rows.push_back(row);
            }
            AgreementOptions agreementOptions;
            agreementOptions.samples = 30;
            agreementOptions.seed = static_cast<std::uint64_t>(e);
            const AgreementResult result = computeAgreement(data, analysis, rows, options.fit, agreementOptions);
            const MetricAgreement& ssim = rowOf(result, "image.ssim");
            if (ssim.pearsonLow <= rho && rho <= ssim.pearsonHigh) ++covered;
        }
        const double coverage = double(covered) / experiments;
        std::printf("agreement interval coverage at %d conditions: %.3f\n", m, coverage);
        EXPECT_GE(coverage, 0.94) << m << " conditions";
    }
}

// The significant pairs set by hand: (a,b), (a,d), (b,c), (c,d). An error metric (lower is better) with values
// 0.4, 0.3, 0.35, 0.1 orders a<b, a<d, c<d as observers did and b>c against them: 3 of 4.
TEST(MetricAgreement, ShareOfSignificantPairsPredicted) {
    scaling::Dataset data = dataset(4, {15, 18, 19}, 20, 1);
    scaling::Analysis analysis;
    scaling::BlockAnalysis block;
    block.name = "scene";
    block.conditions = conditions;
    block.thurstone.scores = Eigen::Vector4d(-1.5, -0.5, 0.5, 1.5);
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) {
            scaling::PairTest pair;
            pair.test.first = i;
            pair.test.second = j;
            pair.significant = (i == 0 && j == 1) || (i == 0 && j == 3) || (i == 1 && j == 2) || (i == 2 && j == 3);
            block.pairs.push_back(pair);
        }
    analysis.blocks.push_back(block);
    AgreementOptions options;
    options.samples = 20;
    AgreementResult result = computeAgreement(data, analysis, metricRows({0.4, 0.3, 0.35, 0.1}), {}, options);
    const MetricAgreement& flip = rowOf(result, "image.flip_mean");
    EXPECT_EQ(flip.significantPairs, 4);
    EXPECT_EQ(flip.predictedPairs, 3);
    EXPECT_DOUBLE_EQ(flip.predictedShare, 0.75);
    // A tie in the metric is not a prediction.
    result = computeAgreement(data, analysis, metricRows({0.3, 0.3, 0.35, 0.1}), {}, options);
    EXPECT_EQ(rowOf(result, "image.flip_mean").predictedPairs, 2);

    nlohmann::json json = agreementJson(result);
    EXPECT_EQ(json["format"], "skinlab-agreement");
    std::string csv = agreementCsv(result);
    EXPECT_NE(csv.find("\nscene,image.flip_mean,0,4,"), std::string::npos) << csv;
}

TEST(MetricAgreement, ReadsMetricsJsonByStimulus) {
    nlohmann::json metrics = {{"format", "skinlab-metrics"},
                              {"comparisons",
                               {{{"test", {{"name", "s1"}}}, {"image", {{"flip_mean", 0.25}, {"psnr_db", nullptr}}}},
                                {{"test", {{"name", "other"}}}, {"image", {{"flip_mean", 0.5}}}}}}};
    auto rows = conditionMetricsFromJson(metrics, "m.json", {{"s1", {"scene", "a"}}});
    ASSERT_EQ(rows.size(), 1u);
    EXPECT_EQ(rows[0].condition, "a");
    EXPECT_DOUBLE_EQ(rows[0].values["image.flip_mean"], 0.25);
    EXPECT_TRUE(std::isnan(rows[0].values["image.psnr_db"]));
    EXPECT_THROW(conditionMetricsFromJson(nlohmann::json::object(), "m.json", {}), InputError);
}

} // namespace
} // namespace skinlab::analysis::agreement
