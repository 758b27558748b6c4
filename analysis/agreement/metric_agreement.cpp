#include "analysis/agreement/metric_agreement.h"
#include "common/csv.h"

#include "analysis/scaling/bootstrap.h"
#include "analysis/scaling/profile_likelihood.h"
#include "common/error.h"
#include "common/version.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <map>
#include <mutex>
#include <random>
#include <tuple>

namespace skinlab::analysis::agreement {
namespace {

constexpr double notANumber = std::numeric_limits<double>::quiet_NaN();

nlohmann::json jsonNumber(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }

std::string csvNumber(double value) {
    if (!std::isfinite(value)) return "";
    char text[40];
    std::snprintf(text, sizeof text, "%.9g", value);
    return text;
}

std::string csvText(const std::string& text) { return csvField(text); }

std::vector<double> ranks(const std::vector<double>& values) {
    std::vector<std::size_t> order(values.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return values[a] < values[b]; });
    std::vector<double> rank(values.size());
    for (std::size_t i = 0; i < order.size();) {
        std::size_t j = i;
        while (j + 1 < order.size() && values[order[j + 1]] == values[order[i]]) ++j;
        double mean = 0.5 * static_cast<double>(i + j) + 1.0;
        for (std::size_t k = i; k <= j; ++k) rank[order[k]] = mean;
        i = j + 1;
    }
    return rank;
}

// A value found by a dotted path in a comparison object ("bands.halo.flip_mean"); NaN for null or absent.
double lookUp(const nlohmann::json& object, const std::string& key) {
    const nlohmann::json* node = &object;
    std::size_t start = 0;
    while (true) {
        std::size_t dot = key.find('.', start);
        std::string part = key.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
        if (!node->is_object() || !node->contains(part)) return notANumber;
        node = &(*node)[part];
        if (dot == std::string::npos) break;
        start = dot + 1;
    }
    return node->is_number() ? node->get<double>() : notANumber;
}

} // namespace

const std::vector<MetricDefinition>& metricDefinitions() {
    static const std::vector<MetricDefinition> definitions = [] {
        std::vector<MetricDefinition> list;
        // ColorVideoVDP's JOD against the reference (10 = indistinguishable): higher is closer.
        list.push_back({"cvvdp_jod", "ColorVideoVDP (JOD)", true});
        for (const char* region : {"image", "skin"}) {
            std::string r = region;
            list.push_back({r + ".psnr_db", "PSNR (" + r + ")", true});
            list.push_back({r + ".ssim", "SSIM (" + r + ")", true});
            list.push_back({r + ".delta_e00_mean", "mean ΔE00 (" + r + ")", false});
            list.push_back({r + ".delta_e00_p95", "p95 ΔE00 (" + r + ")", false});
            list.push_back({r + ".flip_mean", "mean FLIP (" + r + ")", false});
        }
        for (const char* band : {"halo", "bleed", "spill", "interior"}) {
            std::string b = band;
            list.push_back({"bands." + b + ".delta_e00_mean", "mean ΔE00 (" + b + ")", false});
            list.push_back({"bands." + b + ".flip_mean", "mean FLIP (" + b + ")", false});
            if (b != "interior") list.push_back({"bands." + b + ".leak_energy", "leak energy (" + b + ")", false});
        }
        return list;
    }();
    return definitions;
}

std::vector<ConditionMetrics>
conditionMetricsFromJson(const nlohmann::json& metrics, const std::string& file,
                         const std::map<std::string, std::pair<std::string, std::string>>& conditionOfStimulus) {
    if (!metrics.is_object() || metrics.value("format", "") != "skinlab-metrics" || !metrics.contains("comparisons") ||
        !metrics["comparisons"].is_array())
        throwInput(file, "format", "not a metrics.json written by `skinlab analyze metrics`");
    std::vector<ConditionMetrics> out;
    for (const nlohmann::json& comparison : metrics["comparisons"]) {
        if (!comparison.contains("test") || !comparison["test"].contains("name")) continue;
        std::string name = comparison["test"]["name"].get<std::string>();
        auto found = conditionOfStimulus.find(name);
        if (found == conditionOfStimulus.end()) continue;
        ConditionMetrics row{found->second.first, found->second.second, name, {}};
        for (const MetricDefinition& metric : metricDefinitions())
            row.values[metric.key] = lookUp(comparison, metric.key);
        out.push_back(std::move(row));
    }
    return out;
}

double pearsonCorrelation(const std::vector<double>& x, const std::vector<double>& y) {
    const std::size_t n = x.size();
    if (n < 3 || y.size() != n) return notANumber;
    double mx = std::accumulate(x.begin(), x.end(), 0.0) / double(n);
    double my = std::accumulate(y.begin(), y.end(), 0.0) / double(n);
    double sxy = 0.0, sxx = 0.0, syy = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        sxy += (x[i] - mx) * (y[i] - my);
        sxx += (x[i] - mx) * (x[i] - mx);
        syy += (y[i] - my) * (y[i] - my);
    }
    if (!(sxx > 0.0) || !(syy > 0.0)) return notANumber;
    return std::clamp(sxy / std::sqrt(sxx * syy), -1.0, 1.0);
}

double spearmanCorrelation(const std::vector<double>& x, const std::vector<double>& y) {
    if (x.size() < 3 || y.size() != x.size()) return notANumber;
    return pearsonCorrelation(ranks(x), ranks(y));
}

std::pair<double, double> correlationInterval(double r, int n, bool spearman, double extraVariance, double level) {
    if (n < 4 || !std::isfinite(r)) return {notANumber, notANumber};
    const double clamped = std::clamp(r, -0.999999, 0.999999);
    const double variance = (spearman ? 1.0 + 0.5 * r * r : 1.0) / double(n - 3) + std::max(0.0, extraVariance);
    const double z = std::atanh(clamped);
    const double half = scaling::normalQuantile(0.5 + 0.5 * level) * std::sqrt(variance);
    return {std::tanh(z - half), std::tanh(z + half)};
}

namespace {

// Sample Spearman ρ of n continuous values as the integer D = Σ d² of rank differences (ρ = 1 − 6D/(n³ − n)).
// The sampling distribution of D at n under a bivariate normal of Pearson correlation `pearson` (Monte Carlo,
// fixed seed), or, for pearson = 0, exactly over all n! orderings (n ≤ 8): the null of correlationPValue.
std::vector<double> spearmanDistribution(int n, double pearson, int draws, std::uint64_t seed) {
    const int maximum = (n * n * n - n) / 3; // largest D
    std::vector<double> probability(static_cast<std::size_t>(maximum + 1), 0.0);
    if (pearson == 0.0 && n <= 8) {
        std::vector<int> order(static_cast<std::size_t>(n));
        std::iota(order.begin(), order.end(), 0);
        double total = 0.0;
        do {
            int d = 0;
            for (int i = 0; i < n; ++i) d += (order[i] - i) * (order[i] - i);
            probability[static_cast<std::size_t>(d)] += 1.0;
            total += 1.0;
        } while (std::next_permutation(order.begin(), order.end()));
        for (double& p : probability) p /= total;
        return probability;
    }
    std::mt19937_64 random(seed);
    std::normal_distribution<double> normal(0.0, 1.0);
    std::vector<double> x(static_cast<std::size_t>(n)), y(static_cast<std::size_t>(n));
    const double other = std::sqrt(std::max(0.0, 1.0 - pearson * pearson));
    for (int draw = 0; draw < draws; ++draw) {
        for (int i = 0; i < n; ++i) {
            x[i] = normal(random);
            y[i] = pearson * x[i] + other * normal(random);
        }
        const std::vector<double> rx = ranks(x), ry = ranks(y);
        double d = 0.0;
        for (int i = 0; i < n; ++i) d += (rx[i] - ry[i]) * (rx[i] - ry[i]);
        probability[static_cast<std::size_t>(std::lround(d))] += 1.0 / draws;
    }
    return probability;
}

} // namespace

std::pair<double, double> spearmanExactInterval(double rho, int n, double level) {
    if (n < 3 || n > 8 || !std::isfinite(rho)) return {notANumber, notANumber};
    // The belt: population Spearman correlations on a grid of 0.01 (Pearson 2 sin(πρ/6) for the normal model),
    // each with its sampling distribution of D; ρ belongs to the interval when the observed D is not in either tail
    // of mass below (1 − level)/2. Cached per n (the same for every call).
    static std::mutex mutex;
    static std::map<int, std::vector<std::vector<double>>> belts;
    const double cube = double(n) * n * n - n;
    const int observed = static_cast<int>(std::lround((1.0 - rho) * cube / 6.0));
    const double tail = 0.5 * (1.0 - level);
    std::lock_guard<std::mutex> lock(mutex);
    auto& belt = belts[n];
    if (belt.empty())
        for (int g = -99; g <= 99; ++g)
            belt.push_back(
                spearmanDistribution(n, g == 0 ? 0.0 : 2.0 * std::sin(M_PI * g / 600.0), 10000,
                                     scaling::mixSeed(20270, static_cast<std::uint64_t>(g + 100 + 1000 * n))));
    double low = notANumber, high = notANumber;
    for (int g = -99; g <= 99; ++g) {
        const std::vector<double>& probability = belt[static_cast<std::size_t>(g + 99)];
        double atMost = 0.0, atLeast = 0.0; // P(D ≤ observed), P(D ≥ observed): ρ̂ ≥ / ≤ the observed ρ̂
        for (std::size_t d = 0; d < probability.size(); ++d) {
            if (static_cast<int>(d) <= observed) atMost += probability[d];
            if (static_cast<int>(d) >= observed) atLeast += probability[d];
        }
        if (atMost > tail && atLeast > tail) {
            if (!std::isfinite(low)) low = g / 100.0;
            high = g / 100.0;
        }
    }
    // The grid ends at ±0.99: an observed ρ̂ of ±1 is consistent with ±1 itself.
    if (high >= 0.99 && rho >= 1.0 - 1e-12) high = 1.0;
    if (low <= -0.99 && rho <= -1.0 + 1e-12) low = -1.0;
    return {low, high};
}

double correlationPValue(const std::vector<double>& x, const std::vector<double>& y, bool spearman) {
    auto correlation = [&](const std::vector<double>& a, const std::vector<double>& b) {
        return spearman ? spearmanCorrelation(a, b) : pearsonCorrelation(a, b);
    };
    const double observed = correlation(x, y);
    const std::size_t n = x.size();
    if (!std::isfinite(observed)) return notANumber;
    if (n <= 8) {
        std::vector<std::size_t> order(n);
        std::iota(order.begin(), order.end(), 0);
        std::vector<double> permuted(n);
        long long extreme = 0, total = 0;
        do {
            for (std::size_t i = 0; i < n; ++i) permuted[i] = y[order[i]];
            const double r = correlation(x, permuted);
            if (std::isfinite(r) && std::abs(r) >= std::abs(observed) - 1e-12) ++extreme;
            ++total;
        } while (std::next_permutation(order.begin(), order.end()));
        return double(extreme) / double(total);
    }
    const double variance = (spearman ? 1.0 + 0.5 * observed * observed : 1.0) / double(n - 3);
    const double z = std::atanh(std::clamp(observed, -0.999999, 0.999999)) / std::sqrt(variance);
    return std::erfc(std::abs(z) / std::sqrt(2.0));
}

namespace {

// Metric values per condition of this block (null where a condition has none).
std::vector<const ConditionMetrics*> metricsByCondition(const scaling::BlockAnalysis& block,
                                                        const std::vector<ConditionMetrics>& metrics) {
    const int m = static_cast<int>(block.conditions.size());
    std::vector<const ConditionMetrics*> byCondition(static_cast<std::size_t>(m), nullptr);
    for (const ConditionMetrics& row : metrics) {
        if (row.block != block.name) continue;
        auto it = std::find(block.conditions.begin(), block.conditions.end(), row.condition);
        if (it != block.conditions.end()) byCondition[static_cast<std::size_t>(it - block.conditions.begin())] = &row;
    }
    return byCondition;
}

// A condition's value of a metric (NaN where the condition or the metric has none).
double metricValue(const std::vector<const ConditionMetrics*>& byCondition, int condition, const std::string& key) {
    const ConditionMetrics* row = byCondition[static_cast<std::size_t>(condition)];
    if (!row) return notANumber;
    auto found = row->values.find(key);
    return found == row->values.end() ? notANumber : found->second;
}

// Bootstrap over observers: resample, re-fit the scale (none without two observers).
std::vector<Eigen::VectorXd> resampledScores(const scaling::BlockAnalysis& block, const scaling::BlockData& data,
                                             const scaling::FitOptions& fit, const AgreementOptions& options) {
    const int observers = data.observerCount();
    std::vector<Eigen::VectorXd> resampled;
    if (observers >= 2 && data.hasObservers) {
        for (int b = 0; b < options.samples; ++b) {
            std::mt19937_64 random(scaling::mixSeed(options.seed, static_cast<std::uint64_t>(b)));
            std::uniform_int_distribution<int> pick(0, observers - 1);
            Eigen::VectorXd weights = Eigen::VectorXd::Zero(observers);
            for (int k = 0; k < observers; ++k) weights[pick(random)] += 1.0;
            scaling::FitOptions options1 = fit;
            options1.model = scaling::Model::Thurstone;
            resampled.push_back(
                scaling::fitScores(data.weightedCounts(weights), options1, &block.thurstone.scores).scores);
        }
    }
    return resampled;
}

// The observers' share of the uncertainty: the variance of atanh(r) over the resamples.
double zVariance(const std::vector<double>& samples) {
    if (samples.size() < 2) return 0.0;
    double mean = 0.0, squares = 0.0;
    for (double r : samples) mean += std::atanh(std::clamp(r, -0.999999, 0.999999));
    mean /= double(samples.size());
    for (double r : samples) {
        const double d = std::atanh(std::clamp(r, -0.999999, 0.999999)) - mean;
        squares += d * d;
    }
    return squares / double(samples.size() - 1);
}

// One metric's agreement with the block's scale: correlations, their intervals and p-values, and the significant
// pairs it orders like the observers.
MetricAgreement metricAgreement(const scaling::BlockAnalysis& block, const MetricDefinition& definition,
                                const std::vector<const ConditionMetrics*>& byCondition,
                                const std::vector<Eigen::VectorXd>& resampled, const AgreementOptions& options) {
    const int m = static_cast<int>(block.conditions.size());
    auto value = [&](int condition, const std::string& key) { return metricValue(byCondition, condition, key); };
    MetricAgreement row;
    row.block = block.name;
    row.metric = definition;
    std::vector<int> used;
    for (int i = 0; i < m; ++i)
        if (std::isfinite(value(i, definition.key))) used.push_back(i);
    row.conditions = static_cast<int>(used.size());
    std::vector<double> x, y;
    for (int i : used) {
        x.push_back(value(i, definition.key));
        y.push_back(block.thurstone.scores[i]);
    }
    row.pearson = pearsonCorrelation(x, y);
    row.spearman = spearmanCorrelation(x, y);
    std::vector<double> pearsons, spearmans;
    for (const Eigen::VectorXd& scores : resampled) {
        std::vector<double> yb;
        for (int i : used) yb.push_back(scores[i]);
        double p = pearsonCorrelation(x, yb), s = spearmanCorrelation(x, yb);
        if (std::isfinite(p)) pearsons.push_back(p);
        if (std::isfinite(s)) spearmans.push_back(s);
    }
    row.bootstrapSamples = static_cast<int>(pearsons.size());
    std::tie(row.pearsonLow, row.pearsonHigh) =
        correlationInterval(row.pearson, row.conditions, false, zVariance(pearsons), options.level);
    std::tie(row.spearmanLow, row.spearmanHigh) =
        correlationInterval(row.spearman, row.conditions, true, zVariance(spearmans), options.level);
    if (row.conditions < kFewConditions) {
        // Few conditions: Fisher's z is far too narrow near ±1 (ρ̂ = 1 at 5 conditions gave [0.91, 1.00] with an
        // exact p of 0.017); the exact belt, widened by the observers' share as the z interval is.
        const auto [low, high] = spearmanExactInterval(row.spearman, row.conditions, options.level);
        row.spearmanLow = std::min(low, row.spearmanLow);
        row.spearmanHigh = std::max(high, row.spearmanHigh);
    }
    row.pearsonP = correlationPValue(x, y, false);
    row.spearmanP = correlationPValue(x, y, true);

    // Pairs the observers separated significantly: does the metric order them the same way?
    for (const scaling::PairTest& pair : block.pairs) {
        if (!pair.significant) continue;
        int i = pair.test.first, j = pair.test.second;
        double vi = value(i, definition.key), vj = value(j, definition.key);
        if (!std::isfinite(vi) || !std::isfinite(vj)) continue;
        ++row.significantPairs;
        double perceived = block.thurstone.scores[i] - block.thurstone.scores[j];
        double predicted = (definition.higherIsBetter ? 1.0 : -1.0) * (vi - vj);
        if (predicted != 0.0 && (predicted > 0.0) == (perceived > 0.0)) ++row.predictedPairs;
    }
    row.predictedShare = row.significantPairs ? double(row.predictedPairs) / double(row.significantPairs) : notANumber;
    return row;
}

// Holm over the block's metrics: naming the metric with the smallest p picks one of many.
void holmOverMetrics(std::vector<MetricAgreement>& rows, const std::string& blockName) {
    std::vector<MetricAgreement*> tested;
    for (MetricAgreement& row : rows)
        if (row.block == blockName && std::isfinite(row.spearmanP)) tested.push_back(&row);
        else if (row.block == blockName) row.spearmanPHolm = notANumber;
    std::sort(tested.begin(), tested.end(),
              [](const MetricAgreement* a, const MetricAgreement* b) { return a->spearmanP < b->spearmanP; });
    double running = 0.0;
    for (std::size_t k = 0; k < tested.size(); ++k) {
        running = std::max(running, std::min(1.0, double(tested.size() - k) * tested[k]->spearmanP));
        tested[k]->spearmanPHolm = running;
    }
}

} // namespace

AgreementResult computeAgreement(const scaling::Dataset& dataset, const scaling::Analysis& analysis,
                                 const std::vector<ConditionMetrics>& metrics, const scaling::FitOptions& fit,
                                 const AgreementOptions& options) {
    AgreementResult result;
    result.options = options;
    const auto& definitions = metricDefinitions();
    for (const scaling::BlockAnalysis& block : analysis.blocks) {
        auto data = std::find_if(dataset.blocks.begin(), dataset.blocks.end(),
                                 [&](const scaling::BlockData& b) { return b.name == block.name; });
        if (data == dataset.blocks.end()) continue;
        const int m = static_cast<int>(block.conditions.size());
        BlockScale scale{block.name, block.conditions, {}};
        for (int i = 0; i < m; ++i) scale.jod.push_back(block.thurstone.scores[i]);
        result.scales.push_back(scale);

        const std::vector<const ConditionMetrics*> byCondition = metricsByCondition(block, metrics);
        int withMetrics = 0;
        for (int i = 0; i < m; ++i) {
            if (byCondition[static_cast<std::size_t>(i)]) ++withMetrics;
            else if (std::any_of(metrics.begin(), metrics.end(), [&](const auto& r) { return r.block == block.name; }))
                result.warnings.push_back(block.name + ": condition \"" +
                                          block.conditions[static_cast<std::size_t>(i)] +
                                          "\" has no metric values (not compared with a reference)");
        }
        if (withMetrics == 0) {
            result.warnings.push_back(block.name + ": no condition has metric values; no agreement computed");
            continue;
        }

        const std::vector<Eigen::VectorXd> resampled = resampledScores(block, *data, fit, options);
        for (const MetricDefinition& definition : definitions)
            result.rows.push_back(metricAgreement(block, definition, byCondition, resampled, options));
        holmOverMetrics(result.rows, block.name);
        const int used = static_cast<int>(std::count_if(byCondition.begin(), byCondition.end(),
                                                        [](const ConditionMetrics* row) { return row != nullptr; }));
        if (used < kFewConditions)
            result.warnings.push_back(block.name + ": correlations over " + std::to_string(used) +
                                      " conditions: their intervals are wide and the metric with the largest one "
                                      "is weakly determined (" +
                                      std::to_string(kFewConditions) + " or more conditions recommended)");
    }
    return result;
}

nlohmann::json agreementJson(const AgreementResult& result) {
    nlohmann::json scales = nlohmann::json::array();
    for (const BlockScale& scale : result.scales) {
        nlohmann::json jod = nlohmann::json::object();
        for (std::size_t i = 0; i < scale.conditions.size(); ++i) jod[scale.conditions[i]] = scale.jod[i];
        scales.push_back({{"block", scale.block}, {"jod", jod}});
    }
    nlohmann::json rows = nlohmann::json::array();
    for (const MetricAgreement& row : result.rows)
        rows.push_back({{"block", row.block},
                        {"metric", row.metric.key},
                        {"label", row.metric.label},
                        {"higher_is_better", row.metric.higherIsBetter},
                        {"conditions", row.conditions},
                        {"pearson", jsonNumber(row.pearson)},
                        {"pearson_low", jsonNumber(row.pearsonLow)},
                        {"pearson_high", jsonNumber(row.pearsonHigh)},
                        {"spearman", jsonNumber(row.spearman)},
                        {"spearman_low", jsonNumber(row.spearmanLow)},
                        {"spearman_high", jsonNumber(row.spearmanHigh)},
                        {"pearson_p", jsonNumber(row.pearsonP)},
                        {"spearman_p", jsonNumber(row.spearmanP)},
                        {"spearman_p_holm", jsonNumber(row.spearmanPHolm)},
                        {"significant_pairs", row.significantPairs},
                        {"predicted_pairs", row.predictedPairs},
                        {"predicted_share", jsonNumber(row.predictedShare)},
                        {"bootstrap_samples", row.bootstrapSamples}});
    const char* interval =
        "Fisher z over the conditions (Spearman: Bonett-Wright variance), widened by the variance of "
        "atanh(r) over a bootstrap of the observers (Thurstone scale re-fitted per resample); "
        "Spearman below 8 conditions: the hull of that and the exact interval (consistent with the "
        "exact p)";
    return {{"format", "skinlab-agreement"},
            {"version", 1},
            {"skinlab_version", version()},
            {"settings",
             {{"bootstrap_samples", result.options.samples},
              {"seed", result.options.seed},
              {"level", result.options.level},
              {"interval", interval},
              {"p_value", "two-sided, no association: exact over all orderings of the conditions up to 8, else Fisher "
                          "z; spearman_p_holm: Holm over the block's metrics"},
              {"correlation_sign", "raw: metric against JOD (an error metric that agrees with observers correlates "
                                   "negatively)"},
              {"pairs", "pairs significant in the scale analysis; a tie in the metric counts as not predicted"}}},
            {"scales", scales},
            {"agreement", rows},
            {"warnings", result.warnings}};
}

std::string agreementCsv(const AgreementResult& result) {
    std::string out =
        "block,metric,higher_is_better,conditions,pearson,pearson_low,pearson_high,spearman,spearman_low,"
        "spearman_high,pearson_p,spearman_p,spearman_p_holm,significant_pairs,predicted_pairs,predicted_share\n";
    for (const MetricAgreement& row : result.rows) {
        out += csvText(row.block) + "," + row.metric.key + "," + (row.metric.higherIsBetter ? "1" : "0") + "," +
               std::to_string(row.conditions);
        for (double v : {row.pearson, row.pearsonLow, row.pearsonHigh, row.spearman, row.spearmanLow, row.spearmanHigh,
                         row.pearsonP, row.spearmanP, row.spearmanPHolm})
            out += "," + csvNumber(v);
        out += "," + std::to_string(row.significantPairs) + "," + std::to_string(row.predictedPairs) + "," +
               csvNumber(row.predictedShare) + "\n";
    }
    return out;
}

} // namespace skinlab::analysis::agreement
