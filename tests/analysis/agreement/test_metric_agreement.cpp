// Metrics against the JOD scale on synthetic studies with known answers: correlations computed by hand, intervals
// that collapse to the estimate when every observer answered alike, and the share of significant pairs a metric
// orders correctly when the significant pairs are set by hand.
#include "analysis/agreement/metric_agreement.h"

#include "analysis/scaling/comparison_data.h"
#include "analysis/scaling/responses.h"
#include "common/error.h"

#include <gtest/gtest.h>

#include <cmath>

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
// count), so the re-fitted scale and every correlation equal the estimate, and the intervals have zero width.
TEST(MetricAgreement, IdenticalObserversGiveIntervalsAtTheEstimate) {
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
    EXPECT_NEAR(flip.pearsonLow, flip.pearson, 1e-9);
    EXPECT_NEAR(flip.pearsonHigh, flip.pearson, 1e-9);
    EXPECT_DOUBLE_EQ(flip.spearmanLow, -1.0);
    EXPECT_DOUBLE_EQ(flip.spearmanHigh, -1.0);
    EXPECT_EQ(flip.bootstrapSamples, 50);
    // A metric with no values is undefined, never a number.
    const MetricAgreement& psnr = rowOf(result, "image.psnr_db");
    EXPECT_EQ(psnr.conditions, 0);
    EXPECT_TRUE(std::isnan(psnr.pearson));
    EXPECT_TRUE(std::isnan(psnr.pearsonLow));
    EXPECT_TRUE(std::isnan(psnr.predictedShare));
}

// Observers who differ: the interval contains the estimate and has positive width; the order of the scale is
// clear (8 observers), so Spearman stays −1 in every resample.
TEST(MetricAgreement, VaryingObserversGiveAnIntervalAroundTheEstimate) {
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
    EXPECT_GT(flip.pearsonHigh - flip.pearsonLow, 1e-6);
    EXPECT_DOUBLE_EQ(flip.spearmanLow, -1.0);
    EXPECT_DOUBLE_EQ(flip.spearmanHigh, -1.0);
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
