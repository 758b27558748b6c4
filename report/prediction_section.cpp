#include "report/prediction_section.h"

#include "analysis/agreement/metric_agreement.h"
#include "analysis/metrics/cvvdp.h"
#include "analysis/metrics/metric_render.h"
#include "common/html.h"
#include "report/report_plots.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <tuple>

namespace skinlab::report {
namespace scaling = skinlab::analysis::scaling;
namespace agreement = skinlab::analysis::agreement;

std::vector<PredictionAgreement> predictionAgreement(const experiments::StudyDefinition& definition,
                                                     const nlohmann::json& manifest,
                                                     const scaling::Analysis& analysis) {
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    std::map<std::string, double> predictedOfStimulus;
    if (manifest.contains("stimuli"))
        for (const nlohmann::json& s : manifest["stimuli"])
            if (s.contains("predicted") && s["predicted"].is_object() && s["predicted"].contains("jod") &&
                s["predicted"]["jod"].is_number())
                predictedOfStimulus[s["id"].get<std::string>()] = s["predicted"]["jod"].get<double>();
    std::vector<PredictionAgreement> out;
    for (const scaling::BlockAnalysis& block : analysis.blocks) {
        // Predicted JOD of each of the block's conditions (through the stimulus showing it).
        std::vector<double> predicted(block.conditions.size(), nan);
        for (const experiments::StudyStimulus& s : definition.stimuli) {
            if (s.block != block.name || s.condition.empty()) continue;
            const auto it = std::find(block.conditions.begin(), block.conditions.end(), s.condition);
            const auto p = predictedOfStimulus.find(s.id);
            if (it != block.conditions.end() && p != predictedOfStimulus.end())
                predicted[static_cast<std::size_t>(it - block.conditions.begin())] = p->second;
        }
        int anchor = -1;
        for (std::size_t i = 0; i < predicted.size(); ++i)
            if (std::isfinite(predicted[i]) &&
                (anchor < 0 || predicted[i] > predicted[static_cast<std::size_t>(anchor)]))
                anchor = static_cast<int>(i);
        if (anchor < 0) continue;
        PredictionAgreement a;
        a.block = block.name;
        a.anchor = block.conditions[static_cast<std::size_t>(anchor)];
        for (std::size_t i = 0; i < predicted.size(); ++i) {
            if (!std::isfinite(predicted[i])) continue;
            const int k = static_cast<int>(i);
            a.conditions.push_back(block.conditions[i]);
            a.predicted.push_back(predicted[i] - predicted[static_cast<std::size_t>(anchor)]);
            a.measured.push_back(block.thurstone.scores[k] - block.thurstone.scores[anchor]);
            double low = nan, high = nan;
            if (k == anchor) low = high = 0.0;
            for (const scaling::PairTest& pair : block.pairs) {
                if (k == anchor) break;
                if (pair.test.first == k && pair.test.second == anchor) low = pair.test.low, high = pair.test.high;
                if (pair.test.first == anchor && pair.test.second == k) low = -pair.test.high, high = -pair.test.low;
            }
            a.low.push_back(low);
            a.high.push_back(high);
        }
        if (a.conditions.size() < 3) continue;
        double xy = 0.0, xx = 0.0, squares = 0.0;
        for (std::size_t i = 0; i < a.predicted.size(); ++i) {
            xy += a.predicted[i] * a.measured[i];
            xx += a.predicted[i] * a.predicted[i];
            squares += (a.measured[i] - a.predicted[i]) * (a.measured[i] - a.predicted[i]);
        }
        a.slope = xx > 0 ? xy / xx : nan;
        a.rmse = std::sqrt(squares / double(a.predicted.size()));
        a.spearman = agreement::spearmanCorrelation(a.predicted, a.measured);
        std::tie(a.spearmanLow, a.spearmanHigh) =
            agreement::correlationInterval(a.spearman, static_cast<int>(a.predicted.size()), true, 0.0, 0.95);
        out.push_back(std::move(a));
    }
    return out;
}

std::vector<ParticipantPrediction> participantPredictions(const nlohmann::json& manifest,
                                                          const std::filesystem::path& stimuliFolder,
                                                          const std::vector<std::pair<std::string, double>>& viewing) {
    std::vector<ParticipantPrediction> out;
    if (viewing.empty() || !manifest.contains("stimuli")) return out;
    // The predicted stimuli and their references, by block.
    struct Predicted {
        std::string block, png, referencePng, display;
        double jod = 0.0;
    };
    std::map<std::string, std::string> pngOf;
    for (const nlohmann::json& s : manifest["stimuli"])
        pngOf[s["id"].get<std::string>()] = s["files"]["png"].get<std::string>();
    std::vector<Predicted> predicted;
    for (const nlohmann::json& s : manifest["stimuli"])
        if (s.contains("predicted") && s["predicted"].contains("jod") &&
            pngOf.count(s["predicted"].value("reference", "")))
            predicted.push_back({s["block"].get<std::string>(), s["files"]["png"].get<std::string>(),
                                 pngOf[s["predicted"]["reference"].get<std::string>()],
                                 s["predicted"].value("display", std::string("standard_fhd")),
                                 s["predicted"]["jod"].get<double>()});
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
                const metrics::CvvdpDisplay display =
                    metrics::applyCvvdpOverrides(metrics::cvvdpDisplay(p.display), overrides);
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
                                  const std::vector<ParticipantPrediction>& participants) {
    if (agreementRows.empty()) return {};
    std::ostringstream html;
    html << "<h2 id=\"prediction\">Predicted and measured</h2><p class=\"note\">Each condition's JOD predicted by "
            "ColorVideoVDP against the block's reference"
         << (display.empty() ? std::string() : " (display " + escapeHtml(display) + ")")
         << ", and the JOD the observers' answers gave, both as differences to the condition predicted closest to the "
            "reference (the anchor). Dashed: measured = predicted. Bars: the measured difference's interval. Slope: "
            "least squares through the anchor (1 = the study saw the differences the model predicts; below 1, "
            "smaller ones). Spearman's interval: over the conditions (Fisher z, Bonett–Wright).</p>\n";
    for (const PredictionAgreement& a : agreementRows) {
        std::vector<ScatterPoint> points;
        for (std::size_t i = 0; i < a.conditions.size(); ++i)
            points.push_back({a.conditions[i], a.predicted[i], a.measured[i], a.low[i], a.high[i]});
        ScatterOptions options;
        options.identity = true;
        options.yLabel = "measured Δ JOD";
        html << "<h3 id=\"prediction-" << escapeHtml(a.block) << "\">" << escapeHtml(a.block) << " (anchor <em>"
             << escapeHtml(a.anchor) << "</em>)</h3><div class=\"scatters\"><figure>"
             << scatterSvg(points, "predicted Δ JOD", options) << "</figure></div>"
             << "<p>Slope " << formatNumber(a.slope, 2) << ", RMSE " << formatNumber(a.rmse, 2)
             << " JOD, Spearman ρ = " << formatNumber(a.spearman, 2) << " "
             << correlationIntervalText(a.spearmanLow, a.spearmanHigh, static_cast<int>(a.conditions.size()))
             << " over " << a.conditions.size() << " conditions"
             << (static_cast<int>(a.conditions.size()) < agreement::kFewConditions && std::isfinite(a.spearmanLow)
                     ? " (few conditions: a wide interval)"
                     : "")
             << ".</p>\n<table><thead><tr><th class=\"l\">condition</th><th>predicted Δ</th><th>measured Δ</th>"
                "<th>interval</th></tr></thead><tbody>";
        for (std::size_t i = 0; i < a.conditions.size(); ++i)
            html << "<tr><td class=\"l\">" << escapeHtml(a.conditions[i]) << "</td><td>"
                 << formatNumber(a.predicted[i], 2) << "</td><td>" << formatNumber(a.measured[i], 2) << "</td><td>["
                 << formatNumber(a.low[i], 2) << ", " << formatNumber(a.high[i], 2) << "]</td></tr>";
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
