#pragma once
// Matched profiles (docs/pathtraced.md, "Matched profiles"): the edge response of Cycles' random walk
// (RANDOM_WALK_FIXED_RADIUS) on a flat semi-infinite skin slab, and the per-channel radii that make it match the
// edge response of d'Eon's sum of Gaussians, the profile of the screen-space methods.
//
// Measurement: a hard sun lights the slab from straight above over x < 0 only (a plate invisible to the camera cuts
// it off at x = 0); an orthographic camera looks at a strip across the edge. The diffuse radiance L(x) at x > 0 is
// the light that travelled further than x in one direction inside the slab, so E(x) = L(x) / (L(x) + L(−x)) is the
// edge response 1 − ∫_{−∞}^{x} a(t) dt of the profile's 1-D marginal a (exact for any radial profile, whatever
// the slab's total albedo). A fixed-radius random walk is scale-free: radius r gives E_r(x) = E_1(x / r), so one
// render at r = 1 mm serves every radius; the fit minimises Σ (E_1(x_k / r) − E_dEon(x_k))² over x_k in (0, 8] mm,
// with E_dEon(x) = Σ w_i · ½ erfc(x / √(2 v_i)).
#include <array>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace skinlab::renderer::pathtraced {

struct EdgeMeasurementSettings {
    int samples = 256;
    int seed = 0;
    int pixels = 2048; // along the strip
    int rows = 8;      // across it (averaged; Blender renders at least 4)
    // The strip covers x in [−half, +half] at radius 1 mm; a skin-coloured walk of radius 1 mm leaves E < 1e-4
    // beyond 1 mm, so ±4 mm holds the whole response at 0.004 mm pixels.
    double halfLengthMm = 4.0;
    std::array<double, 3> albedo{0.60, 0.42, 0.34}; // subsurface colour (the built-in scenes' skin)
    // Empty: radius 1 mm in every channel (the scale-free measurement). Otherwise the radius comes from the
    // subsurface colour through this table, as pathtraced.radius_model = "albedo" builds it (keys "albedo": knots,
    // "radius": three lists of mm), and x is in mm: an end-to-end check of the shader's table.
    nlohmann::json radiusTable;
    std::string blender = "blender";
    int threads = 0;
};

struct EdgeResponse {
    std::vector<double> xMm;                  // pixel centres x > 0 (radius 1 mm)
    std::array<std::vector<double>, 3> value; // E(x) per channel
    std::array<double, 3> plateau{};          // L(x) + L(−x), averaged: the lit slab's diffuse radiance
    std::string blenderVersion;
    double renderSeconds = 0.0;
};

// Renders the edge scene with Blender (temporary folder; kept with its log on failure).
EdgeResponse measureEdgeResponse(const EdgeMeasurementSettings& settings);

// EEVEE's subsurface kernel (Blender 3.x, source/blender/gpu/intern/gpu_material.c, compute_sss_kernel; applied by
// draw/engines/eevee/shaders/effect_subsurface_frag.glsl): a 1-D kernel k(t) ∝ exp(−|t|/d) + exp(−|t|/(3d)) on
// |t| ≤ 16 d (Burley's radial profile r·R(r), Christensen & Burley 2015, Eq. 3, used as a 1-D weight), applied along
// x and then along y, with d = radius · 0.6 / (4π · s(1)) and s(A) = 1.9 − A + 3.5 (A − 0.8)² evaluated at A = 1
// (Christensen & Burley 2015, Eq. 6; Blender's code fixes the albedo at 1 and calls 0.6 empirical). Across a
// straight edge the second pass integrates to 1, so E(x) = ∫_x^{16d} k / ∫_{−16d}^{16d} k, in closed form.
// The kernel depends on x / d only: radius r gives E_r(x) = E_1(x / r), as the random walk's edge response does.
inline constexpr double kEeveeBurleyDPerRadius = 0.6 / (4.0 * 3.14159265358979323846 * 1.04);
inline constexpr double kEeveeBurleyTruncation = 16.0; // in units of d
double eeveeEdgeResponseAt(double xMm, double radiusMm);
// E_1 sampled like a measurement (pixel centres over (0, 16 d] at radius 1 mm, 4096 of them), for fitRadii.
EdgeResponse eeveeEdgeResponse();

// d'Eon's edge response per channel at x mm.
double deonEdgeResponse(int channel, double xMm);

struct ProfileFit {
    std::array<double, 3> radiusMm{}; // fitted radius per channel
    std::array<double, 3> rmsError{}; // RMS of E_fit − E_dEon over the fit range
    std::array<double, 3> maxError{};
    std::array<double, 3> initialRmsError{}; // the same with the radii before the fit (for comparison)
};

// How well E_1(x / r) at given radii matches d'Eon, per channel: the RMS and largest difference over (0, range]
// mm (as fitRadii measures them), and two widths relative to d'Eon's (ratio − 1): the integral ∫_0^∞ E dx (the
// mean distance light crosses the edge by) and the distance at which E falls to 0.1.
struct ProfileMatch {
    std::array<double, 3> radiusMm{};
    std::array<double, 3> rmsError{};
    std::array<double, 3> maxError{};
    std::array<double, 3> integralError{};
    std::array<double, 3> crossingError{};
};
ProfileMatch matchProfile(const EdgeResponse& response, const std::array<double, 3>& radiusMm, double fitRangeMm = 8.0,
                          double stepMm = 0.01);
// d'Eon's widths: ∫_0^∞ E_dEon dx = Σ w_i σ_i / √(2π), and the x where E_dEon = level.
double deonEdgeIntegral(int channel);
double deonCrossing(int channel, double level);
// The walk's: r · ∫ E_1 (midpoint rule over the pixels), and r · the first x where E_1 (interpolated) ≤ level.
double edgeIntegral(const EdgeResponse& response, int channel, double radiusMm);
double edgeCrossing(const EdgeResponse& response, int channel, double radiusMm, double level);

// A least-squares polynomial of degree `degree` in albedo through ln r (the per-albedo fits of a sweep), evaluated at
// the same albedos: smooths the fits' noise along the albedo. `rmsLogResidual` (optional) gets the RMS of
// ln r − polynomial, i.e. the relative residual.
std::vector<double> smoothRadii(const std::vector<double>& albedo, const std::vector<double>& radiusMm, int degree,
                                double* rmsLogResidual = nullptr);

// The edge response as fit-profile writes it (edge_response.csv: x_mm_at_radius_1mm,E_R,E_G,E_B), for a sweep
// that resumes from the renders it already made.
EdgeResponse readEdgeResponseCsv(const std::filesystem::path& path);

// Fits the radius of each channel (golden-section search on log r after a coarse scan).
ProfileFit fitRadii(const EdgeResponse& response, const std::array<double, 3>& initialRadiusMm, double fitRangeMm = 8.0,
                    double stepMm = 0.01);

// E_1(x / r) by linear interpolation (0 beyond the measured range).
double scaledEdgeResponse(const EdgeResponse& response, int channel, double radiusMm, double xMm);

// A plot of the fit (log E against x, measured-and-scaled solid, d'Eon dashed, one colour per channel) as a PNG.
void writeFitPlot(const std::filesystem::path& path, const EdgeResponse& response, const ProfileFit& fit,
                  double rangeMm = 6.0);

} // namespace skinlab::renderer::pathtraced
