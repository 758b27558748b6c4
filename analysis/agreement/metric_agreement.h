#pragma once
// Image metrics against perception (docs/metrics.md, "Metrics against perception"): for each block of a study
// whose stimuli were scored against a reference, the Pearson and Spearman correlations between every metric and
// the JOD scale across the block's conditions, and the share of the pairs that observers separated significantly
// whose order the metric predicts. The conditions are the sample a correlation is computed over (a handful, as a
// rule), so its interval is Fisher's z interval over the conditions (Bonett & Wright 2000 for Spearman), widened by
// the variance a bootstrap over observers (each resample re-fits the scale) adds; its p value is exact (all
// permutations of the conditions) for up to 8 conditions.
#include "analysis/scaling/scale_analysis.h"

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace skinlab::analysis::agreement {

// A metric as `analyze metrics` writes it: the JSON path inside one comparison ("image.flip_mean",
// "bands.halo.delta_e00_mean"), and whether a larger value means closer to the reference.
struct MetricDefinition {
    std::string key;
    std::string label;
    bool higherIsBetter = false;
};
const std::vector<MetricDefinition>& metricDefinitions();

// The metric values of one condition of one block (NaN where undefined).
struct ConditionMetrics {
    std::string block;
    std::string condition;
    std::string stimulus;
    std::map<std::string, double> values; // by MetricDefinition::key
};

// Reads the comparisons of a metrics.json (format "skinlab-metrics"), keeping those whose test name is a key of
// `conditionOfStimulus` (stimulus id → (block, condition)). Throws InputError naming `file` for a file that is
// not a metrics.json.
std::vector<ConditionMetrics>
conditionMetricsFromJson(const nlohmann::json& metrics, const std::string& file,
                         const std::map<std::string, std::pair<std::string, std::string>>& conditionOfStimulus);

struct AgreementOptions {
    int samples = 1000; // bootstrap resamples of the observers
    std::uint64_t seed = 1;
    double level = 0.95; // two-sided interval
};

// Fewer conditions than this in a block: a warning that its correlations are weakly determined.
inline constexpr int kFewConditions = 8;

struct MetricAgreement {
    std::string block;
    MetricDefinition metric;
    int conditions = 0; // conditions with a finite value of the metric (and a JOD score)
    double pearson = 0.0, pearsonLow = 0.0, pearsonHigh = 0.0; // metric vs JOD; NaN when undefined
    double spearman = 0.0, spearmanLow = 0.0, spearmanHigh = 0.0;
    double pearsonP = 0.0, spearmanP = 0.0; // two-sided p of no correlation (exact permutation for ≤ 8 conditions)
    double spearmanPHolm = 0.0;             // spearmanP after Holm's correction over the block's metrics
    int significantPairs = 0;               // pairs of these conditions separated significantly (scale analysis)
    int predictedPairs = 0;      // of them, pairs the metric orders as the observers did (ties: not predicted)
    double predictedShare = 0.0; // predicted / significant; NaN without a significant pair
    int bootstrapSamples = 0;    // resamples with a defined correlation
};

struct BlockScale {
    std::string block;
    std::vector<std::string> conditions;
    std::vector<double> jod; // per condition
};

struct AgreementResult {
    AgreementOptions options;
    std::vector<BlockScale> scales;
    std::vector<MetricAgreement> rows; // per block, per metric in metricDefinitions() order
    std::vector<std::string> warnings;
};

// `analysis` must come from analyzeDataset(dataset, ...) with `fit`; conditions of a block without metric values
// are left out of that block's correlations (with a warning).
AgreementResult computeAgreement(const scaling::Dataset& dataset, const scaling::Analysis& analysis,
                                 const std::vector<ConditionMetrics>& metrics, const scaling::FitOptions& fit,
                                 const AgreementOptions& options);

// Pearson correlation; NaN for fewer than 3 values or a constant variable.
double pearsonCorrelation(const std::vector<double>& x, const std::vector<double>& y);
// Spearman's ρ: Pearson of the ranks, ties sharing their mean rank.
double spearmanCorrelation(const std::vector<double>& x, const std::vector<double>& y);

// Interval of a correlation `r` over `n` conditions at `level`: tanh(atanh r ± z·se) with se² = c/(n − 3) +
// `extraVariance` (of atanh r; the observers' share), c = 1 for Pearson, 1 + r²/2 for Spearman (Bonett & Wright
// 2000). NaN for n < 4.
std::pair<double, double> correlationInterval(double r, int n, bool spearman, double extraVariance, double level);
// Interval of the population Spearman correlation from an observed ρ̂ over n ≤ 8 conditions, by inverting the
// exact sampling distribution (Neyman's belt on a grid of 0.01; a bivariate normal model away from 0, all n!
// orderings at 0): it excludes 0 exactly when correlationPValue's two-sided exact p is below 1 − level, and at
// 5 conditions ρ̂ = 1 gives [0.32, 1] (a true ρ of 0.79 gives ρ̂ = 1 in 14 % of studies). NaN outside 3 ≤ n ≤ 8.
std::pair<double, double> spearmanExactInterval(double rho, int n, double level);
// Two-sided p of |correlation| ≥ |observed| under no association: exact over all n! orderings for n ≤ 8, else
// from Fisher's z (variance 1/(n − 3), Spearman (1 + r²/2)/(n − 3)).
double correlationPValue(const std::vector<double>& x, const std::vector<double>& y, bool spearman);

nlohmann::json agreementJson(const AgreementResult& result); // format "skinlab-agreement", version 1
std::string agreementCsv(const AgreementResult& result);     // one row per block and metric

} // namespace skinlab::analysis::agreement
