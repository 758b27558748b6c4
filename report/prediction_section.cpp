#include "report/prediction_section.h"

#include "analysis/agreement/metric_agreement.h"
#include "analysis/scaling/bootstrap.h"
#include "analysis/metrics/cvvdp.h"
#include "analysis/metrics/metric_render.h"
#include "common/html.h"
#include "report/report_plots.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <tuple>

namespace skinlab::report {
namespace scaling = skinlab::analysis::scaling;
namespace agreement = skinlab::analysis::agreement;

namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// Slope of y on x with an intercept, and the RMS of y − x about its mean (n − 1 dof); NaN where undefined.
std::pair<double, double> slopeAndRmse(const std::vector<double>& x, const std::vector<double>& y) {
    const auto n = static_cast<double>(x.size());
    if (x.size() < 3) return {kNan, kNan};
    double mx = 0.0, my = 0.0, md = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) mx += x[i] / n, my += y[i] / n, md += (y[i] - x[i]) / n;
    double xy = 0.0, xx = 0.0, squares = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        xy += (x[i] - mx) * (y[i] - my);
        xx += (x[i] - mx) * (x[i] - mx);
        squares += (y[i] - x[i] - md) * (y[i] - x[i] - md);
    }
    return {xx > 0.0 ? xy / xx : kNan, std::sqrt(squares / (n - 1.0))};
}

// Student's t quantile at probability p with `df` degrees of freedom (Hill 1970's series, ample for 2 ≤ df).
double studentQuantile(double p, int df) {
    const double z = scaling::normalQuantile(p), n = df;
    const double z2 = z * z;
    return z + z * (z2 + 1.0) / (4.0 * n) + z * ((5.0 * z2 + 16.0) * z2 + 3.0) / (96.0 * n * n) +
           z * (((3.0 * z2 + 19.0) * z2 + 17.0) * z2 - 15.0) / (384.0 * n * n * n);
}

// The interval of `estimate` from its bootstrap over `observers` observers: estimate − bias ± t·sd·√(n/(n − 1)),
// bias = mean(resamples) − estimate when `biasCorrected`, t with n − 1 degrees of freedom. The percentile interval
// of the resampled slopes covered the true slope in 86 % of simulated 5-condition studies at 10 observers; this
// one in 97 % (docs/report.md). NaN with fewer than 20 finite resamples.
std::pair<double, double> bootstrapInterval(double estimate, std::vector<double> values, int observers, double level,
                                            bool biasCorrected) {
    std::erase_if(values, [](double v) { return !std::isfinite(v); });
    if (values.size() < 20 || observers < 2) return {kNan, kNan};
    double mean = 0.0, variance = 0.0;
    for (double v : values) mean += v / double(values.size());
    for (double v : values) variance += (v - mean) * (v - mean) / double(values.size() - 1);
    const double centre = biasCorrected ? 2.0 * estimate - mean : estimate;
    const double half = studentQuantile(0.5 + 0.5 * level, observers - 1) * std::sqrt(variance) *
                        std::sqrt(double(observers) / double(observers - 1));
    return {centre - half, centre + half};
}

// The bootstrap of slope and RMSE: observers resampled (the scale re-fitted), and the conditions too from
// kFewConditions on.
void bootstrapAgreement(PredictionAgreement& a, const std::vector<int>& used, const scaling::BlockAnalysis& block,
                        const scaling::BlockData& data, const PredictionOptions& options) {
    const int observers = data.observerCount();
    if (!data.hasObservers || observers < 2) return;
    a.overConditions = static_cast<int>(used.size()) >= agreement::kFewConditions;
    scaling::FitOptions fit = options.fit;
    fit.model = scaling::Model::Thurstone;
    // `noise`: each resample's RMSE about the full data's scores (every condition once), what noise alone gives.
    std::vector<double> slopes, rmses, noise;
    for (int b = 0; b < options.samples; ++b) {
        std::mt19937_64 random(scaling::mixSeed(options.seed, static_cast<std::uint64_t>(b)));
        std::uniform_int_distribution<int> pick(0, observers - 1);
        Eigen::VectorXd weights = Eigen::VectorXd::Zero(observers);
        for (int k = 0; k < observers; ++k) weights[pick(random)] += 1.0;
        const Eigen::VectorXd scores =
            scaling::fitScores(data.weightedCounts(weights), fit, &block.thurstone.scores).scores;
        std::vector<double> x, y;
        std::uniform_int_distribution<std::size_t> condition(0, used.size() - 1);
        for (std::size_t k = 0; k < used.size(); ++k) {
            const std::size_t c = a.overConditions ? condition(random) : k;
            x.push_back(a.predicted[c]);
            y.push_back(scores[used[c]]);
        }
        const auto [slope, rmse] = slopeAndRmse(x, y);
        slopes.push_back(slope);
        rmses.push_back(rmse);
        std::vector<double> full, resampled;
        for (const int k : used) full.push_back(block.thurstone.scores[k]), resampled.push_back(scores[k]);
        noise.push_back(slopeAndRmse(full, resampled).second);
    }
    std::tie(a.slopeLow, a.slopeHigh) = bootstrapInterval(a.slope, slopes, observers, options.level, false);
    // The RMSE includes the measurement noise, which inflates it: its bootstrap bias is removed; never below 0.
    std::tie(a.rmseLow, a.rmseHigh) = bootstrapInterval(a.rmse, rmses, observers, options.level, true);
    a.rmseLow = std::max(a.rmseLow, 0.0);
    a.rmseHigh = std::max(a.rmseHigh, 0.0);
    // At its boundary (a true RMSE of 0) that interval alone starts above 0 too often: in 13–17 % of simulated
    // 5-condition studies whose truth was the prediction (10 and 20 observers). A test of RMSE = 0 also decides the
    // low end: where the RMSE stays below what noise alone reaches in `level` of the resamples (their RMSE about
    // the full data's scores, scaled by √(n/(n − 1)) for n observers), the interval starts at 0.
    std::erase_if(noise, [](double v) { return !std::isfinite(v); });
    if (noise.size() >= 20 && std::isfinite(a.rmse)) {
        std::sort(noise.begin(), noise.end());
        const auto index = static_cast<std::size_t>(std::ceil(options.level * double(noise.size()))) - 1;
        const double scale = std::sqrt(double(observers) / double(observers - 1));
        if (a.rmse <= scale * noise[std::min(index, noise.size() - 1)]) a.rmseLow = 0.0;
        a.rmseHigh = std::max(a.rmseHigh, a.rmseLow);
    }
    a.bootstrapSamples = options.samples;
}

} // namespace

std::optional<PredictionAgreement> blockPredictionAgreement(const scaling::BlockAnalysis& block,
                                                            const std::vector<double>& predicted,
                                                            const scaling::BlockData* data,
                                                            const PredictionOptions& options) {
    std::vector<int> used;
    int anchor = -1;
    for (std::size_t i = 0; i < predicted.size(); ++i) {
        const int k = static_cast<int>(i);
        if (!std::isfinite(predicted[i]) || (i < block.measured.size() && !block.measured[i])) continue;
        used.push_back(k);
        if (anchor < 0 || predicted[i] > predicted[static_cast<std::size_t>(anchor)]) anchor = k;
    }
    if (used.size() < 3) return std::nullopt;
    PredictionAgreement a;
    a.block = block.name;
    a.anchor = block.conditions[static_cast<std::size_t>(anchor)];
    a.observers = static_cast<int>(block.observers.size());
    double predictedMean = 0.0, measuredMean = 0.0;
    for (int k : used) {
        predictedMean += (predicted[k] - predicted[anchor]) / double(used.size());
        measuredMean += block.thurstone.scores[k] / double(used.size());
    }
    const double shift = predictedMean - measuredMean;
    for (int k : used) {
        a.conditions.push_back(block.conditions[static_cast<std::size_t>(k)]);
        a.predicted.push_back(predicted[k] - predicted[anchor]);
        a.measured.push_back(block.thurstone.scores[k] + shift);
        a.low.push_back(block.low[k] + shift);
        a.high.push_back(block.high[k] + shift);
    }
    std::tie(a.slope, a.rmse) = slopeAndRmse(a.predicted, a.measured);
    a.slopeLow = a.slopeHigh = a.rmseLow = a.rmseHigh = kNan;
    if (data) bootstrapAgreement(a, used, block, *data, options);
    const int n = static_cast<int>(used.size());
    a.spearman = agreement::spearmanCorrelation(a.predicted, a.measured);
    a.spearmanP = agreement::correlationPValue(a.predicted, a.measured, true);
    std::tie(a.spearmanLow, a.spearmanHigh) =
        n < agreement::kFewConditions ? agreement::spearmanExactInterval(a.spearman, n, options.level)
                                      : agreement::correlationInterval(a.spearman, n, true, 0.0, options.level);
    return a;
}

std::vector<formats::ManifestEntry> storedManifestEntries(const nlohmann::json& manifest) {
    if (!manifest.is_object() || !manifest.contains("stimuli")) return {};
    return formats::manifestEntriesFromJson(manifest["stimuli"], "the study's stored manifest.json");
}

std::vector<PredictionAgreement> predictionAgreement(const experiments::StudyDefinition& definition,
                                                     const nlohmann::json& manifest, const scaling::Analysis& analysis,
                                                     const scaling::Dataset* dataset,
                                                     const PredictionOptions& options) {
    std::map<std::string, double> predictedOfStimulus;
    for (const formats::ManifestEntry& s : storedManifestEntries(manifest))
        if (s.predicted) predictedOfStimulus[s.id] = s.predicted->jod;
    std::vector<PredictionAgreement> out;
    for (const scaling::BlockAnalysis& block : analysis.blocks) {
        // Predicted JOD of each of the block's conditions (through the stimulus showing it).
        std::vector<double> predicted(block.conditions.size(), kNan);
        for (const experiments::StudyStimulus& s : definition.stimuli) {
            if (s.block != block.name || s.condition.empty()) continue;
            const auto it = std::find(block.conditions.begin(), block.conditions.end(), s.condition);
            const auto p = predictedOfStimulus.find(s.id);
            if (it != block.conditions.end() && p != predictedOfStimulus.end())
                predicted[static_cast<std::size_t>(it - block.conditions.begin())] = p->second;
        }
        const scaling::BlockData* data = nullptr;
        if (dataset)
            for (const scaling::BlockData& candidate : dataset->blocks)
                if (candidate.name == block.name) data = &candidate;
        if (auto a = blockPredictionAgreement(block, predicted, data, options)) out.push_back(std::move(*a));
    }
    return out;
}

std::vector<ParticipantPrediction> participantPredictions(const nlohmann::json& manifest,
                                                          const std::filesystem::path& stimuliFolder,
                                                          const std::vector<std::pair<std::string, double>>& viewing) {
    std::vector<ParticipantPrediction> out;
    if (viewing.empty()) return out;
    const std::vector<formats::ManifestEntry> entries = storedManifestEntries(manifest);
    // The predicted stimuli and their references, by block.
    struct Predicted {
        std::string block, png, referencePng;
        metrics::CvvdpDisplay display; // the prediction's, named or custom
        double jod = 0.0;
    };
    std::map<std::string, std::string> pngOf;
    for (const formats::ManifestEntry& s : entries) pngOf[s.id] = s.files.png;
    std::vector<Predicted> predicted;
    for (const formats::ManifestEntry& s : entries)
        if (s.predicted && pngOf.count(s.predicted->reference))
            predicted.push_back({s.block, s.files.png, pngOf[s.predicted->reference],
                                 s.predicted->displayModel
                                     ? metrics::cvvdpDisplayOf(*s.predicted->displayModel)
                                     : metrics::cvvdpDisplay(s.predicted->display.empty() ? std::string("standard_fhd")
                                                                                          : s.predicted->display),
                                 s.predicted->jod});
    if (predicted.empty()) return out;
    std::map<std::string, metrics::MetricRender> images;
    auto image = [&](const std::string& png) -> const cv::Mat& {
        auto it = images.find(png);
        if (it == images.end())
            it = images
                     .emplace(png, metrics::loadMetricRender(stimuliFolder / png, metrics::RenderRole::test,
                                                             metrics::ImageEncoding::srgb))
                     .first;
        return it->second.beauty;
    };
    std::map<double, std::vector<double>> byPpd; // predictions per distinct ppd, in `predicted` order
    for (const auto& [observer, ppd] : viewing) {
        const double key = ppd;
        if (!byPpd.count(key)) {
            std::vector<double> jods;
            for (const Predicted& p : predicted) {
                metrics::CvvdpDisplayOverrides overrides;
                overrides.pixelsPerDegree = key;
                const metrics::CvvdpDisplay display = metrics::applyCvvdpOverrides(p.display, overrides);
                jods.push_back(metrics::cvvdp(image(p.referencePng), image(p.png), display, false).jod);
            }
            byPpd[key] = std::move(jods);
        }
        const std::vector<double>& jods = byPpd[key];
        ParticipantPrediction row{observer, ppd, 0.0, 0.0, false, static_cast<int>(predicted.size())};
        for (std::size_t i = 0; i < predicted.size(); ++i) {
            const double change = std::abs(jods[i] - predicted[i].jod);
            row.meanChange += change / double(predicted.size());
            row.largestChange = std::max(row.largestChange, change);
            for (std::size_t j = 0; j < predicted.size(); ++j)
                if (predicted[j].block == predicted[i].block &&
                    (predicted[i].jod > predicted[j].jod) != (jods[i] > jods[j]) &&
                    predicted[i].jod != predicted[j].jod)
                    row.orderChanged = true;
        }
        out.push_back(row);
    }
    return out;
}

std::string predictionSectionHtml(const std::vector<PredictionAgreement>& agreementRows, const std::string& display,
                                  const std::vector<ParticipantPrediction>& participants, int simulatedObservers) {
    if (agreementRows.empty()) return {};
    std::ostringstream html;
    html << "<h2 id=\"prediction\">Predicted and measured</h2><p class=\"note\">Each condition's JOD predicted by "
            "ColorVideoVDP against the block's reference"
         << (display.empty() ? std::string() : " (display " + escapeHtml(display) + ")")
         << ", as the difference to the condition predicted closest to the reference (the anchor), and the JOD the "
            "observers' answers gave, shifted as a whole onto the predictions' mean (the measured scale's zero is "
            "arbitrary; no condition, the anchor included, is a fixed point). Dashed: measured = predicted. Bars: each "
            "measured score's interval. Slope: least squares with an intercept (1 = the study saw the differences the "
            "model predicts; below 1, smaller ones); RMSE about the mean difference. Their intervals: bootstrap over "
            "observers, each resample re-fitting the scale (and over conditions too from "
         << agreement::kFewConditions
         << " conditions): over a handful of conditions a slope of 0.75 can be noise. Spearman's ρ with its exact "
            "p over all orderings of the conditions and an interval consistent with it.</p>\n";
    if (simulatedObservers > 0)
        html << "<p class=\"warning\"><strong>Simulated observers.</strong> " << simulatedObservers
             << " participants were simulated by <code>skinlab study simulate</code>: their answers come from the "
                "truth given to it. If that truth was this prediction (<code>--truth predicted</code>), the agreement "
                "below is circular: it shows how well the study recovers its own input, not whether ColorVideoVDP "
                "predicts what people see.</p>\n";
    for (const PredictionAgreement& a : agreementRows) {
        std::vector<ScatterPoint> points;
        for (std::size_t i = 0; i < a.conditions.size(); ++i)
            points.push_back({a.conditions[i], a.predicted[i], a.measured[i], a.low[i], a.high[i]});
        ScatterOptions options;
        options.identity = true;
        options.yLabel = "measured JOD (shifted)";
        auto interval = [](double low, double high) {
            return std::isfinite(low) && std::isfinite(high)
                       ? " [" + formatNumber(low, 2) + ", " + formatNumber(high, 2) + "]"
                       : std::string(" (no interval: fewer than two observers)");
        };
        html << "<h3 id=\"prediction-" << escapeHtml(a.block) << "\">" << escapeHtml(a.block) << " (anchor <em>"
             << escapeHtml(a.anchor) << "</em>)</h3><div class=\"scatters\"><figure>"
             << scatterSvg(points, "predicted Δ JOD", options) << "</figure></div>"
             << "<p>Slope " << formatNumber(a.slope, 2) << interval(a.slopeLow, a.slopeHigh) << ", RMSE "
             << formatNumber(a.rmse, 2) << " JOD" << interval(a.rmseLow, a.rmseHigh) << " ("
             << (a.overConditions ? "bootstrap over observers and conditions" : "bootstrap over observers") << ", "
             << a.observers << " observers), Spearman ρ = " << formatNumber(a.spearman, 2) << " "
             << correlationIntervalText(a.spearmanLow, a.spearmanHigh, static_cast<int>(a.conditions.size()))
             << ", exact p = " << formatNumber(a.spearmanP, 3) << ", over " << a.conditions.size() << " conditions"
             << (static_cast<int>(a.conditions.size()) < agreement::kFewConditions && std::isfinite(a.spearmanLow)
                     ? " (few conditions: a wide interval)"
                     : "")
             << ".</p>\n<table><thead><tr><th class=\"l\">condition</th><th>predicted Δ</th><th>measured</th>"
                "<th>interval</th></tr></thead><tbody>";
        for (std::size_t i = 0; i < a.conditions.size(); ++i)
            html << "<tr><td class=\"l\">" << escapeHtml(a.conditions[i]) << "</td><td>"
                 << formatNumber(a.predicted[i], 2) << "</td><td>" << formatNumber(a.measured[i], 2) << "</td><td>"
                 << intervalText(a.low[i], a.high[i], 2) << "</td></tr>";
        html << "</tbody></table>\n";
    }
    html << "<h3>With each participant's own display</h3>";
    if (participants.empty()) {
        html << "<p class=\"note\">No participant calibrated their display (the design's <code>[display] calibrate"
                "</code>), so every prediction uses the display model above.</p>\n";
    } else {
        html << "<p class=\"note\">Where the card calibration recorded a participant's pixels per degree, every "
                "prediction again with that geometry (the same display model otherwise): how much it moves.</p>"
                "<table><thead><tr><th class=\"l\">participant</th><th>pixels per degree</th><th>mean |Δ| JOD</th>"
                "<th>largest |Δ| JOD</th><th>predicted order</th></tr></thead><tbody>";
        for (const ParticipantPrediction& p : participants)
            html << "<tr><td class=\"l\">" << escapeHtml(p.observer) << "</td><td>"
                 << formatNumber(p.pixelsPerDegree, 1) << "</td><td>" << formatNumber(p.meanChange, 3) << "</td><td>"
                 << formatNumber(p.largestChange, 3) << "</td><td>" << (p.orderChanged ? "changes" : "same")
                 << "</td></tr>";
        html << "</tbody></table>\n";
    }
    return html.str();
}

} // namespace skinlab::report
