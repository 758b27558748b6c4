#pragma once
// The halo, bleed, spill and interior bands (docs/metrics.md, "Bands"). The construction
// follows Middlebury's depth-discontinuity regions (Scharstein & Szeliski 2002) and Boundary IoU's
// resolution-relative bands (Cheng et al. 2021): every width is the projected SSS support radius
// ρ(p) = r_w · f_px / D(p) in pixels, never a fixed number of pixels, so band areas scale with the resolution.
#include <array>
#include <string_view>

#include <opencv2/core.hpp>

namespace skinlab::metrics {

enum class Band { halo, bleed, spill, interior };
inline constexpr std::array<Band, 4> allBands = {Band::halo, Band::bleed, Band::spill, Band::interior};
std::string_view bandName(Band band); // "halo", "bleed", "spill", "interior"

struct BandGeometry {
    double supportRadiusWorld = 0.0; // r_w = sss_radius_mm / mm_per_unit, world units
    double focalLengthPixels = 0.0;  // f_px = (H/2) / tan(fovY/2)
};

struct ErrorBands {
    cv::Mat skin;            // CV_8UC1 255 where mask ≥ 0.5
    cv::Mat projectedRadius; // CV_32FC1 ρ(p) in pixels; 0 where the depth is not finite and positive
    cv::Mat depthEdges;      // CV_8UC1 255 on both pixels of every 4-neighbour pair whose depths differ by > r_w
    cv::Mat materialEdges;   // CV_8UC1 255 on both pixels of every skin/non-skin 4-neighbour pair at continuous depth
    std::array<cv::Mat, 4> masks; // CV_8UC1 255 inside the band, indexed by Band; pairwise disjoint
    const cv::Mat& mask(Band band) const { return masks[static_cast<size_t>(band)]; }
};

// Builds the bands from the reference's linear depth (CV_32FC1, world units, background +inf) and skin mask
// (CV_32FC1, 0..1). A pixel is "within ρ" of an edge when the distance from its centre to the nearest edge
// pixel's centre, plus half a pixel (the edge lies between the two pixels of the pair), is at most ρ.
ErrorBands buildErrorBands(const cv::Mat& depth, const cv::Mat& skinMask, const BandGeometry& geometry);

} // namespace skinlab::metrics
