#pragma once
// ColorVideoVDP for still images, own implementation of R. K. Mantiuk, P. Hanji, M. Ashraf, Y. Asano, A. Chapiro,
// "ColorVideoVDP: A visual difference predictor for image, video and display distortions", ACM Trans. Graph.
// 43(4), 2024 (SIGGRAPH), following the public reference implementation gfxdisp/ColorVideoVDP, release v0.5.6
// (MIT): its parameters, CSF table, display models and colour spaces ship in analysis/metrics/cvvdp/ and are
// embedded in the library (docs/metrics.md, "ColorVideoVDP").
//
// An image is a one-frame video: the achromatic sustained channel and the two chromatic channels (red-green,
// yellow-violet) of DKL, each decomposed into a decimated Laplacian pyramid of Weber contrast, weighted by the
// castleCSF sensitivity at the local background luminance, passed through cross-channel mutual masking, pooled
// over space, bands and channels, and mapped to JOD (10 = no visible difference).
#include "formats/stimulus_manifest.h"

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace skinlab::metrics {

// A display: photometry (how a relative linear value becomes cd/m²) and geometry (pixels per degree).
struct CvvdpDisplay {
    std::string name;        // the model's key in display_models.json, or "custom"
    std::string description; // the model's "name" text
    // How the input maps to luminance. "sRGB", "PQ", "HLG" and gamma numbers ("2.2") are display-encoded
    // transfer functions: the relative linear input v (the decoded pixel value, 1 = white) gives
    // L = (Y_peak − Y_black)·clamp(v, 0, 1) + Y_black + Y_refl. "linear" is an absolute-linear display:
    // L = clamp(v·Y_peak, max(0.005, Y_black), Y_peak) + Y_refl.
    std::string eotf = "sRGB";
    double peakLuminance = 200.0;    // Y_peak, cd/m²
    double contrast = 1000.0;        // Y_peak / Y_black
    double ambientIlluminance = 0.0; // E_amb, lux
    double reflectivity = 0.005;     // k_refl of the panel
    double pixelsPerDegree = 0.0;    // at the centre of the screen
    // Geometry as given (0 when the model states the ppd directly): for reports only.
    int resolutionWidth = 0;
    int resolutionHeight = 0;
    double diagonalInches = 0.0;
    double viewingDistanceMetres = 0.0;

    double blackLevel() const { return peakLuminance / contrast; }                                       // Y_black
    double reflectedLevel() const { return ambientIlluminance / 3.14159265358979323846 * reflectivity; } // Y_refl
};

// The named display models of display_models.json, in file order.
std::vector<std::string> cvvdpDisplayNames();

// The named model. Throws InputError "--display: NAME is not one of ..." for an unknown name.
CvvdpDisplay cvvdpDisplay(const std::string& name);

// Pixels per degree at the screen centre of a flat display: width from the diagonal and the aspect ratio of the
// resolution, ppd = 1 / (2·atan(width / (2·pixels·distance)) in degrees) (the reference's display geometry).
double cvvdpPixelsPerDegree(int resolutionWidth, int resolutionHeight, double diagonalInches,
                            double viewingDistanceMetres);

// Changes to a display (a custom display starts from a named model). A given `pixelsPerDegree` fixes the ppd;
// otherwise a change of resolution, diagonal or distance recomputes it from the geometry (which must then be
// complete). Every given value is checked: throws InputError "--display-OPTION: V must be ..." naming the
// command-line option.
struct CvvdpDisplayOverrides {
    std::optional<double> pixelsPerDegree;
    std::optional<std::array<int, 2>> resolution; // width, height in pixels
    std::optional<double> diagonalInches;
    std::optional<double> viewingDistanceMetres;
    std::optional<double> peakLuminance;
    std::optional<double> contrast;
    std::optional<double> ambientIlluminance;
    std::optional<double> reflectivity;
    bool any() const {
        return pixelsPerDegree || resolution || diagonalInches || viewingDistanceMetres || peakLuminance || contrast ||
               ambientIlluminance || reflectivity;
    }
};
CvvdpDisplay applyCvvdpOverrides(CvvdpDisplay display, const CvvdpDisplayOverrides& overrides);

// A display as a stimulus manifest records a custom one (formats::DisplayModel), and back (named "custom"): the
// parameters round-trip exactly, so that metrics read back the display a set's predictions were made on.
formats::DisplayModel displayModelOf(const CvvdpDisplay& display);
CvvdpDisplay cvvdpDisplayOf(const formats::DisplayModel& model);

// One line: "NAME: ppd P, peak Y cd/m², black B, reflected R cd/m², EOTF".
std::string describeCvvdpDisplay(const CvvdpDisplay& display);

// Wall-clock seconds per stage of one call (accumulated over bands).
struct CvvdpStageTimes {
    double colour = 0.0;  // display model and DKL conversion
    double pyramid = 0.0; // Gaussian/Laplacian decomposition and Weber contrast
    double csf = 0.0;     // castleCSF look-ups
    double masking = 0.0; // mutual cross-channel masking and the difference clamp
    double pooling = 0.0; // spatial, band and channel pooling and the JOD mapping
    double heatmap = 0.0; // the per-pixel map (pyramid reconstruction)
};

struct CvvdpResult {
    double jod = 10.0;    // 10 = no visible difference; lower is more visible
    double quality = 0.0; // the pooled difference Q before the JOD mapping
    // Per-pixel visibility, CV_32FC1 (empty when not asked for): the JOD loss 10 − JOD of the per-pixel
    // difference (the reference's "raw" heat map × 10): 0 = invisible, 1 = one JOD.
    cv::Mat map;
    std::vector<double> bandFrequencies;            // cycles per degree, finest first; the baseband last (0.1)
    std::array<std::vector<double>, 3> bandQuality; // per channel (achromatic, red-green, yellow-violet), per band
};

// Compares two linear Rec.709 RGB images (CV_32FC3, channels R, G, B, relative: 1 = display white; see
// CvvdpDisplay::eotf) of the same size on `display`. Throws std::invalid_argument for mismatched or empty
// images. Thread-safe; the parameter files are parsed once per process.
CvvdpResult cvvdp(const cv::Mat& referenceLinear, const cv::Mat& testLinear, const CvvdpDisplay& display,
                  bool computeMap = true, CvvdpStageTimes* times = nullptr);

// The JOD mapping of the reference: 10 − a·Q^e, and below Q = 0.1 the straight line from 10 at Q = 0 to that
// curve's value at 0.1.
double cvvdpQualityToJod(double quality);

// Mean of a visibility map over `mask` (CV_8UC1, non-zero selects; everywhere when empty); NaN when the mask
// selects nothing.
double cvvdpMapMean(const cv::Mat& map, const cv::Mat& mask = {});

} // namespace skinlab::metrics
