#include "analysis/metrics/metrics_run.h"

#include "analysis/metrics/error_heatmap.h"
#include "common/error.h"
#include "common/files.h"

#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <optional>

#include <spdlog/spdlog.h>

namespace skinlab::metrics {
namespace fs = std::filesystem;
namespace {
constexpr double notANumber = std::numeric_limits<double>::quiet_NaN();
}

std::vector<ComparisonRecord> runMetrics(const ComparisonPlan& plan, const MetricsRunOptions& options,
                                         const fs::path& outputFolder) {
    if (plan.jobs.empty()) throwInput("", "", "nothing to compare: no test render besides the reference");
    validateMetricOptions(options.metric);
    if (options.heatmapMax < 0.0 || !std::isfinite(options.heatmapMax))
        throwInput("--heatmap-max", "",
                   std::to_string(options.heatmapMax) + " must be a positive number (0: from the data)");

    // 1. Check every input from its header before any output exists.
    std::map<fs::path, MetricRender> referenceHeaders;
    for (const ComparisonJob& job : plan.jobs) {
        auto found = referenceHeaders.find(job.referencePath);
        if (found == referenceHeaders.end())
            found = referenceHeaders
                        .emplace(job.referencePath,
                                 inspectMetricRender(job.referencePath, RenderRole::reference, options.metric.encoding))
                        .first;
        const MetricRender& reference = found->second;
        if (!reference.plain && !options.metric.sssRadiusMillimetres && !reference.sssRadiusMillimetres)
            throwInput(job.referencePath.string(), "skinlab:sss_radius_mm",
                       "metadata attribute is missing (or give --sss-radius-mm)");
        checkComparable(reference, inspectMetricRender(job.testPath, RenderRole::test, options.metric.encoding));
        // A stimulus set: the presented PNGs, as observers see them, of one size per block.
        if (job.referencePresented.empty() != job.testPresented.empty())
            throw std::logic_error("runMetrics(): a presented image for one of reference and test only");
        if (!job.referencePresented.empty()) {
            const MetricRender shownReference =
                inspectMetricRender(job.referencePresented, RenderRole::test, ImageEncoding::srgb);
            const MetricRender shownTest =
                inspectMetricRender(job.testPresented, RenderRole::test, ImageEncoding::srgb);
            if (shownTest.width != shownReference.width || shownTest.height != shownReference.height)
                throwInput(job.testPresented.string(), "",
                           "size " + std::to_string(shownTest.width) + "x" + std::to_string(shownTest.height) +
                               " differs from the reference's presented image " + job.referencePresented.string() +
                               " (" + std::to_string(shownReference.width) + "x" +
                               std::to_string(shownReference.height) + ")");
        }
    }
    for (const auto& [path, reference] : referenceHeaders)
        if (reference.plain)
            spdlog::info("metrics: {} is a plain image (no depth.Z, mask.Y or skinlab metadata, read as {}): skin and "
                         "band metrics (halo, bleed, spill, interior) skipped",
                         path.string(), imageEncodingName(reference.encoding));

    // 2. Compare, one reference prepared once for all its tests.
    ensureDirectory(outputFolder);
    std::vector<ComparisonRecord> records;
    std::map<fs::path, std::shared_ptr<const PreparedReference>> prepared;
    for (const ComparisonJob& job : plan.jobs) {
        auto found = prepared.find(job.referencePath);
        if (found == prepared.end()) {
            prepared.clear(); // jobs are grouped by reference; keep one in memory at a time
            std::optional<MetricRender> shown;
            if (!job.referencePresented.empty())
                shown = loadMetricRender(job.referencePresented, RenderRole::test, ImageEncoding::srgb);
            auto reference = std::make_shared<const PreparedReference>(
                prepareReference(loadMetricRender(job.referencePath, RenderRole::reference, options.metric.encoding),
                                 options.metric, shown ? &*shown : nullptr));
            found = prepared.emplace(job.referencePath, reference).first;
        }
        const PreparedReference& reference = *found->second;
        spdlog::info("metrics: {} vs {}", job.testName, job.referenceName);
        std::optional<MetricRender> shown;
        if (!job.testPresented.empty())
            shown = loadMetricRender(job.testPresented, RenderRole::test, ImageEncoding::srgb);
        ComparisonResult result =
            compareWithReference(reference, loadMetricRender(job.testPath, RenderRole::test, options.metric.encoding),
                                 options.metric, shown ? &*shown : nullptr);

        ComparisonRecord record;
        record.job = job;
        record.width = reference.displayWidth();
        record.height = reference.displayHeight();
        record.sssRadiusMillimetres = reference.sssRadiusMillimetres;
        record.millimetresPerUnit = reference.render.millimetresPerUnit.value_or(notANumber);
        record.bandsMeasured = result.bandsMeasured;
        record.geometry = reference.geometry;
        record.image = result.image;
        record.skin = result.skin;
        record.bands = result.bands;
        record.cvvdpJod = result.cvvdpJod;
        if (options.heatmaps) {
            // Each map's colour scale from its own data (--heatmap-max fixes the ΔE00 one instead).
            record.heatmapMax =
                options.heatmapMax > 0.0 ? options.heatmapMax : automaticScaleMax(result.deltaE00, 0.01);
            record.flipHeatmapMax = std::min(1.0, automaticScaleMax(result.flip, 0.001));
            record.cvvdpHeatmapMax = automaticScaleMax(result.cvvdpMap, 0.001);
            record.heatmap = "heatmaps/" + job.testName + ".png";
            writeErrorHeatmap(outputFolder / record.heatmap, result.deltaE00, reference.displayBands,
                              record.heatmapMax);
            record.flipHeatmap = "heatmaps/" + job.testName + ".flip.png";
            writeFlipHeatmap(outputFolder / record.flipHeatmap, result.flip, record.flipHeatmapMax);
            record.cvvdpHeatmap = "heatmaps/" + job.testName + ".cvvdp.png";
            writeCvvdpHeatmap(outputFolder / record.cvvdpHeatmap, result.cvvdpMap, record.cvvdpHeatmapMax);
        }
        records.push_back(std::move(record));
    }

    // 3. Tables last.
    writeFileAtomic(outputFolder / "metrics.csv", metricsCsv(records));
    const bool presented = !plan.jobs.empty() && !plan.jobs.front().referencePresented.empty();
    ReportSettings settings{options.metric.exposure, options.heatmapMax,     options.metric.flipPixelsPerDegree(),
                            options.metric.encoding, options.metric.display, presented,
                            options.displaySource};
    writeFileAtomic(outputFolder / "metrics.json",
                    metricsJson(records, settings, plan.blocksWithoutReference).dump(2) + "\n");
    return records;
}

} // namespace skinlab::metrics
