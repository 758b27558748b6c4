#pragma once
// `skinlab analyze metrics` without the command line: check every input, compare, write heat maps, then
// metrics.csv and metrics.json (last, so a complete metrics.json means a complete run). Every file is written
// atomically.
#include "analysis/metrics/metrics_report.h"
#include "analysis/metrics/render_comparison.h"
#include "analysis/metrics/stimulus_set_pairs.h"

#include <filesystem>
#include <vector>

namespace skinlab::metrics {

struct MetricsRunOptions {
    MetricOptions metric;
    double heatmapMax = 0.0; // ΔE00 at the top of the heat map's colour scale; 0 = from each map's data
    bool heatmaps = true;
    // Where metric.display came from, for metrics.json ("the set's predictions", "--display", ...).
    std::string displaySource = "--display";
};

// Inputs are checked (files, channels, metadata, sizes) before anything is written. Returns the records written.
std::vector<ComparisonRecord> runMetrics(const ComparisonPlan& plan, const MetricsRunOptions& options,
                                         const std::filesystem::path& outputFolder);

} // namespace skinlab::metrics
