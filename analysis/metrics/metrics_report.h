#pragma once
// The tables `skinlab analyze metrics` writes: metrics.csv (one row per comparison) and metrics.json
// (format "skinlab-metrics", version 1). Columns and fields: docs/metrics.md, "Outputs".
#include "analysis/metrics/render_comparison.h"
#include "analysis/metrics/stimulus_set_pairs.h"

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace skinlab::metrics {

// One finished comparison, without the per-pixel map.
struct ComparisonRecord {
    ComparisonJob job;
    int width = 0;
    int height = 0;
    double sssRadiusMillimetres = 0.0;
    double millimetresPerUnit = 0.0;
    BandGeometry geometry;
    RegionScores image;
    RegionScores skin;
    std::array<BandScores, 4> bands;
    std::string heatmap;      // path relative to the output folder; "" when heat maps are off
    std::string flipHeatmap;  // the FLIP map, likewise
    std::string cvvdpHeatmap; // the ColorVideoVDP visibility map, likewise
    double cvvdpJod = 10.0;   // ColorVideoVDP (JOD, 10 = no visible difference)
    // The top of each heat map's colour scale (its legend says it): ΔE00, FLIP, JOD loss.
    double heatmapMax = 0.0, flipHeatmapMax = 0.0, cvvdpHeatmapMax = 0.0;
    bool bandsMeasured = true; // false: plain reference, skin and band scores undefined (null / empty cells)
};

struct ReportSettings {
    double exposure = 1.0;
    double heatmapMax = 10.0;
    double pixelsPerDegree = flipDefaultPixelsPerDegree;
    ImageEncoding encoding = ImageEncoding::automatic;
    CvvdpDisplay display = cvvdpDisplay("standard_fhd");
    bool presented = false;                  // display-referred scores on the presented PNGs of a stimulus set
    std::string displaySource = "--display"; // where the display (the viewing geometry) came from
};

// CSV with a header row; NaN (undefined: empty band, no skin) is an empty cell, +inf (PSNR of identical
// images) is "inf". Numbers with 9 significant digits.
std::string metricsCsv(const std::vector<ComparisonRecord>& records);

// NaN and inf become null (docs/metrics.md says which is which).
nlohmann::json metricsJson(const std::vector<ComparisonRecord>& records, const ReportSettings& settings,
                           const std::vector<std::string>& blocksWithoutReference);

// The display encoding, as documented in the outputs.
extern const char* const displayEncodingDescription;

} // namespace skinlab::metrics
