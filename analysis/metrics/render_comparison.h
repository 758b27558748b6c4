#pragma once
// One comparison of a test render with a reference: per-pixel ΔE00, global and skin PSNR/SSIM/ΔE00, and the
// band scores (docs/metrics.md lists every field).
#include "analysis/metrics/cvvdp.h"
#include "analysis/metrics/error_bands.h"
#include "analysis/metrics/flip.h"
#include "analysis/metrics/metric_render.h"

#include <array>
#include <cstddef>
#include <optional>

#include <opencv2/core.hpp>

namespace skinlab::metrics {

struct MetricOptions {
    // Linear multiplier applied to both renders before the display encoding for ΔE00/PSNR/SSIM (docs/metrics.md).
    // 1 keeps the renderer's exposure, which the contract says is already applied.
    double exposure = 1.0;
    // Overrides the reference's skinlab:sss_radius_mm (millimetres) when set.
    std::optional<double> sssRadiusMillimetres;
    // FLIP's pixels per degree of visual angle; 0 (default): the display's (`display.pixelsPerDegree`), so that
    // FLIP and ColorVideoVDP see one viewing geometry.
    double pixelsPerDegree = 0.0;
    // How 8/16-bit and EXR inputs are decoded to linear RGB (plain images; skinlab renders are linear EXRs).
    ImageEncoding encoding = ImageEncoding::automatic;
    // ColorVideoVDP's display (default standard_fhd); the linear input × exposure is the display's relative value.
    CvvdpDisplay display = cvvdpDisplay("standard_fhd");
    // FLIP's pixels per degree: `pixelsPerDegree`, or the display's when it is 0.
    double flipPixelsPerDegree() const { return pixelsPerDegree > 0.0 ? pixelsPerDegree : display.pixelsPerDegree; }
};

// The reference with everything that does not depend on the test render computed once. For a plain reference
// (render.plain) `bands` holds empty masks and `skinLuminanceSum` is 0: only the image-wide scores are defined.
//
// Two images of one stimulus: the render (`render.beauty`, linear, the EXR) and, for a stimulus set, the presented
// image (`presented`: the PNG observers see, tone-mapped, cropped and magnified, decoded with the sRGB EOTF). The
// display-referred scores (ΔE00, PSNR, SSIM, FLIP, ColorVideoVDP) run on the presented image when there is one
// (otherwise on the render × exposure as a display shows it, clipped at its white); the linear score (leak energy)
// always runs on the render, unclipped. `displayBands` are `bands` brought to the size of the display-referred
// image (nearest neighbour: a magnified pixel belongs to the band of its render pixel).
struct PreparedReference {
    MetricRender render;
    cv::Mat presented; // CV_32FC3 display-linear R, G, B in [0, 1]; empty: the render is what is scored
    BandGeometry geometry;
    double sssRadiusMillimetres = 0.0;
    ErrorBands bands;              // on the render's pixels
    ErrorBands displayBands;       // on the display-referred image's pixels (= bands without a presented image)
    cv::Mat lab;                   // CV_64FC3 L*, a*, b* of the display encoding
    cv::Mat luminance;             // CV_64FC1 linear Y (× exposure) of the render, unclipped, for the leak energy
    cv::Mat display;               // CV_64FC3 sRGB-encoded R, G, B on 0–255 for PSNR and SSIM
    double skinLuminanceSum = 0.0; // Σ_skin Y_R
    int displayWidth() const { return presented.empty() ? render.width : presented.cols; }
    int displayHeight() const { return presented.empty() ? render.height : presented.rows; }
};

// Throws InputError "--exposure: V must be a positive number" (or --sss-radius-mm) for a bad option.
void validateMetricOptions(const MetricOptions& options);

// Requires a render loaded with RenderRole::reference (a skinlab render or a plain image). Throws InputError for a non-positive exposure or radius.
// `presented` (optional): the presented image of the reference (MetricRender::beauty of its PNG read as sRGB);
// then the exposure must be 1 (the presented image is scored as shown).
PreparedReference prepareReference(MetricRender reference, const MetricOptions& options,
                                   const MetricRender* presented = nullptr);

struct RegionScores {
    std::size_t pixels = 0;
    double psnrDecibels = 0.0; // +inf when identical on the region
    double ssim = 0.0;         // mean SSIM over the region
    double deltaE00Mean = 0.0;
    double deltaE00P95 = 0.0;  // 95th percentile, linear interpolation between order statistics
    double flipMean = 0.0;     // mean LDR-FLIP over the region (pooled in double)
    double cvvdpMapMean = 0.0; // mean ColorVideoVDP visibility (JOD loss per pixel) over the region
};

struct BandScores {
    std::size_t pixels = 0;
    double fractionOfImage = 0.0;
    double fractionOfSkin = 0.0; // band pixels / skin pixels (NaN without skin)
    double deltaE00Mean = 0.0;   // NaN for an empty band
    double deltaE00P95 = 0.0;    // NaN for an empty band
    double flipMean = 0.0;       // mean LDR-FLIP over the band; NaN for an empty band
    double cvvdpMapMean = 0.0;   // mean ColorVideoVDP visibility over the band; NaN for an empty band
    double excess = 0.0;         // band mean − interior mean; NaN if either is empty
    double leakEnergy = 0.0;     // Σ_band |Y_T − Y_R| / Σ_skin Y_R; NaN without skin luminance
};

struct ComparisonResult {
    bool bandsMeasured = true; // false for a plain reference: `skin` and `bands` are all NaN (0 pixels)
    RegionScores image;
    RegionScores skin;
    std::array<BandScores, 4> bands; // indexed by Band
    cv::Mat deltaE00;                // CV_32FC1 per-pixel ΔE00
    cv::Mat flip;                    // CV_64FC1 per-pixel LDR-FLIP
    double cvvdpJod = 10.0;          // ColorVideoVDP of the whole image on MetricOptions::display
    cv::Mat cvvdpMap;                // CV_32FC1 per-pixel ColorVideoVDP visibility (JOD loss)
    const BandScores& band(Band b) const { return bands[static_cast<std::size_t>(b)]; }
};

// Throws InputError "TEST: size WxH differs from the reference REF (WxH)" and, when both carry skinlab:f_px,
// "TEST: skinlab:f_px: V differs from the reference's V (not the same camera)": the bands need the same camera.
// Works on headers (inspectMetricRender) as well as on loaded renders.
void checkComparable(const MetricRender& reference, const MetricRender& test);

// Checks with checkComparable, then compares. `presented`: the test's presented image, required exactly when the
// reference has one (same size as the reference's).
ComparisonResult compareWithReference(const PreparedReference& reference, const MetricRender& test,
                                      const MetricOptions& options, const MetricRender* presented = nullptr);

// 95th percentile with linear interpolation between order statistics (NumPy's default); NaN when empty.
double percentile95(std::vector<double> values);

} // namespace skinlab::metrics
