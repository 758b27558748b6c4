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

// The display as the manifest records it: its name, and every parameter of a custom one.
formats::Prediction predictionOn(const metrics::CvvdpDisplay& display) {
    formats::Prediction prediction;
    prediction.metric = kMetric;
    prediction.display = display.name;
    if (display.name == "custom") prediction.displayModel = metrics::displayModelOf(display);
    return prediction;
}

} // namespace

PredictionSummary predictStimuli(const fs::path& dir, Manifest& manifest, const PredictionOptions& options) {
    const formats::Prediction on = predictionOn(options.display);
    PredictionSummary summary;
    std::map<std::string, const formats::ManifestEntry*> referenceOf; // block → its reference entry
    for (const formats::ManifestEntry& entry : manifest.stimuli)
        if (entry.reference) referenceOf[entry.block] = &entry;
    for (const auto& [block, reference] : referenceOf) {
        BlockPrediction result{block, reference->id, 10.0, -1.0, 0, false};
        metrics::MetricRender referenceImage;
        bool loaded = false;
        for (formats::ManifestEntry& entry : manifest.stimuli) {
            if (entry.block != block || entry.reference) continue;
            // Up to date: same display, same reference image, same test image.
            const std::optional<formats::Prediction>& old = entry.predicted;
            const bool current = old && old->display == on.display && old->displayModel == on.displayModel &&
                                 old->referencePngSha256 == reference->sha256.png && old->pngSha256 == entry.sha256.png;
            if (!current) {
                if (!loaded) {
                    referenceImage = metrics::loadMetricRender(dir / reference->files.png, metrics::RenderRole::test,
                                                               metrics::ImageEncoding::srgb);
                    loaded = true;
                }
                const metrics::MetricRender test = metrics::loadMetricRender(
                    dir / entry.files.png, metrics::RenderRole::test, metrics::ImageEncoding::srgb);
                formats::Prediction prediction = on;
                prediction.reference = result.reference;
                prediction.jod = metrics::cvvdp(referenceImage.beauty, test.beauty, options.display, false).jod;
                prediction.referencePngSha256 = reference->sha256.png;
                prediction.pngSha256 = entry.sha256.png;
                entry.predicted = prediction;
                ++summary.predicted;
            }
            const double jod = entry.predicted->jod;
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
                      b.block.c_str(), b.conditions, b.lowest, b.highest, b.reference.c_str(),
                      options.display.name.c_str(), b.highest - b.lowest);
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
