#pragma once
// Heat map of the per-pixel ΔE00 with the halo/bleed/spill/interior bands outlined and a colour legend
// (docs/metrics.md, "Heat map").
#include "analysis/metrics/error_bands.h"

#include <filesystem>

#include <opencv2/core.hpp>

namespace skinlab::metrics {

// Renders the picture as BGR 8-bit: the ΔE00 map (CV_32FC1) through the inferno colour map on [0, scaleMax]
// (larger values saturate), band outlines one pixel wide, and a legend panel on the right.
cv::Mat renderErrorHeatmap(const cv::Mat& deltaE00, const ErrorBands& bands, double scaleMax);

// Writes renderErrorHeatmap(...) as a PNG atomically; throws InputError naming the path when it cannot.
void writeErrorHeatmap(const std::filesystem::path& path, const cv::Mat& deltaE00, const ErrorBands& bands,
                       double scaleMax);

// The per-pixel LDR-FLIP map (0..1) through the magma colour map (the paper's choice) with a legend panel.
cv::Mat renderFlipHeatmap(const cv::Mat& flip, double scaleMax = 1.0);
void writeFlipHeatmap(const std::filesystem::path& path, const cv::Mat& flip, double scaleMax = 1.0);

// The per-pixel ColorVideoVDP visibility (JOD loss, CV_32FC1) through the viridis colour map on [0, 1] JOD
// (one JOD and more saturate, as the reference's "threshold" map) with a legend panel.
cv::Mat renderCvvdpHeatmap(const cv::Mat& visibility, double scaleMax = 1.0);
void writeCvvdpHeatmap(const std::filesystem::path& path, const cv::Mat& visibility, double scaleMax = 1.0);

// A colour scale chosen from the data of one figure: the 99th percentile of the finite values rounded up to 1, 2
// or 5 × 10^k (so the map shows its own structure instead of saturating or staying black), and at least
// `minimum`. Heat maps drawn with it say their scale in the legend.
double automaticScaleMax(const cv::Mat& values, double minimum);

} // namespace skinlab::metrics
