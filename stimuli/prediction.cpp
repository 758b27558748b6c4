#include "stimuli/prediction.h"

#include "analysis/metrics/cvvdp.h"
#include "analysis/metrics/metric_render.h"

#include <algorithm>
#include <cstdio>
#include <map>

namespace skinlab::stimuli {
namespace fs = std::filesystem;

namespace {

constexpr const char* kMetric = "ColorVideoVDP v0.5.6";

std::string pngSha(const nlohmann::json& entry) { return entry.at("sha256").at("png").get<std::string>(); }

} // namespace

PredictionSummary predictStimuli(const fs::path& dir, Manifest& manifest, const PredictionOptions& options) {
    const metrics::CvvdpDisplay display = metrics::cvvdpDisplay(options.display);
    PredictionSummary summary;
    std::map<std::string, nlohmann::json*> referenceOf; // block → its reference entry
    for (nlohmann::json& entry : manifest.stimuli)
        if (entry.value("reference", false)) referenceOf[entry.at("block").get<std::string>()] = &entry;
    for (const auto& [block, reference] : referenceOf) {
        BlockPrediction result{block, reference->at("id").get<std::string>(), 10.0, -1.0, 0, false};
        metrics::MetricRender referenceImage;
        bool loaded = false;
        for (nlohmann::json& entry : manifest.stimuli) {
            if (entry.at("block") != block || entry.value("reference", false)) continue;
            // Up to date: same display, same reference image, same test image.
            const nlohmann::json* old = entry.contains("predicted") ? &entry["predicted"] : nullptr;
            const bool current = old && old->value("display", "") == options.display &&
                                 old->value("reference_png_sha256", "") == pngSha(*reference) &&
                                 old->value("png_sha256", "") == pngSha(entry) && old->contains("jod");
            if (!current) {
                if (!loaded) {
                    referenceImage =
                        metrics::loadMetricRender(dir / reference->at("files").at("png").get<std::string>(),
                                                  metrics::RenderRole::test, metrics::ImageEncoding::srgb);
                    loaded = true;
                }
                const metrics::MetricRender test =
                    metrics::loadMetricRender(dir / entry.at("files").at("png").get<std::string>(),
                                              metrics::RenderRole::test, metrics::ImageEncoding::srgb);
                const metrics::CvvdpResult r = metrics::cvvdp(referenceImage.beauty, test.beauty, display, false);
                entry["predicted"] = formats::toJson(formats::Prediction{kMetric, options.display, result.reference,
                                                                         r.jod, pngSha(*reference), pngSha(entry)});
                ++summary.predicted;
            }
            const double jod = entry["predicted"]["jod"].get<double>();
            result.lowest = std::min(result.lowest, jod);
            result.highest = std::max(result.highest, jod);
            ++result.conditions;
        }
        if (result.conditions == 0) continue;
        result.invisible = result.highest - result.lowest < options.invisibleBelow;
        summary.blocks.push_back(result);
    }
    return summary;
}

std::vector<std::string> predictionLines(const PredictionSummary& summary, const PredictionOptions& options) {
    std::vector<std::string> lines;
    char text[512];
    for (const BlockPrediction& b : summary.blocks) {
        std::snprintf(text, sizeof text,
                      "block %s: %d stimuli predicted %.2f–%.2f JOD against %s (ColorVideoVDP, %s; spread %.2f JOD)",
                      b.block.c_str(), b.conditions, b.lowest, b.highest, b.reference.c_str(), options.display.c_str(),
                      b.highest - b.lowest);
        lines.push_back(text);
        if (b.invisible) {
            std::snprintf(text, sizeof text,
                          "warning: block %s: every condition lies within %.2f JOD of the others (less than %.2f): "
                          "a study of this block would hardly resolve them; make the differences visible (views, "
                          "crops, levels) before recruiting",
                          b.block.c_str(), b.highest - b.lowest, options.invisibleBelow);
            lines.push_back(text);
        }
    }
    return lines;
}

} // namespace skinlab::stimuli
