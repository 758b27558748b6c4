#pragma once
// The object-space reference SSS : convolution of per-sample diffuse irradiance × albedo over the
// surface with a radial diffusion profile at true 3-D distances, among skin samples only.
//
// For a skin receiver p and skin sources q within the cutoff radius r_c (3-D distance |p − q| in mm):
//   K_c(p, q) = R_c(|p − q|) · A_q                    (q ≠ p; A_q: the source's area, mm²)
//   K_c(p, p) = ∫_0^a 2πs R_c(s) ds,  a = √(A_p / π)  (the receiver's own disc: exact for the narrow lobes that
//                                                      fall between samples, and finite for Burley's 1/r centre)
//   out_c(p)  = Σ_q K_c(p, q) E_c(q) α_c(q) / Σ_q K_c(p, q)
// (Transport::ThroughTissue, the default below: the sums skip sources across air, and the denominator sums only
// the sources facing the receiver's way.)
// E: irradiance, α: albedo. Non-skin samples neither scatter (they are never sources) nor receive (their output is
// E·α, unblurred). Dividing by Σ K keeps a uniformly lit, uniformly coloured skin surface unchanged and hands the
// energy of the tails beyond r_c and of the quadrature error back to the receiver; the energy carried to non-skin
// neighbours is handed back too (NonSkin::Returns, the default, as the screen-space methods do when they replace
// non-skin taps by the centre colour, renderer/sss/cpu_blur.h) or lost (NonSkin::Absorbs: they count in Σ K).
//
// r_c is the radius outside which every channel of the profile has at most `cutoffTail` of its energy
// (default 1e-3, 0.1 %: 8.0 mm for d'Eon's skin profile at width 3 mm).
#include "renderer/sss/radial_profile.h"
#include "renderer/reference/surface_samples.h"

#include <array>
#include <cstdint>
#include <vector>

namespace skinlab::renderer::reference {

// How light travels between samples (the render method uses ThroughTissue):
//  - Euclidean: every skin source within r_c at its 3-D distance, normalised by Σ K over all of them. Light jumps
//    air gaps under r_c (lips, ear folds), and a thin part lit from the front is dimmed by 1/(1 + T), T the
//    kernel weight of its back face.
//  - ThroughTissue (default): a source counts only when the chord p → q runs inside the body (neither leaves p's
//    surface nor reaches q from outside at more than asin(kAirGapSine) = 10° to the tangent plane; a concave
//    surface of radius R keeps its sources up to 2R · 0.17 mm away, the rest of the kernel's energy is handed back
//    by the normaliser; two faces across a gap g lose each other up to g / 0.17 mm apart), and Σ K of the
//    normaliser holds only the sources facing the receiver's way (n_p · n_q > −½, within 120°: the far side of a
//    thin part faces away by nearly 180°, while a body's edge — a neck's cut, a box's corner — turns by about 90°
//    and is no thin part; at 0 such an edge's sources got the through-light gain): a uniformly lit flat surface
//    stays unchanged, the energy of tails and non-skin neighbours is still handed back, and the light of a thin
//    part's back face adds to its front (through-light) instead of averaging with it.
enum class Transport { Euclidean, ThroughTissue };
inline constexpr float kAirGapSine = 0.17364818f; // sin 10°

// What becomes of the light the profile carries to non-skin neighbours (paint, an eye, another material):
//  - Returns (default): the normaliser holds skin sources only and hands that light back to the receiver, as the
//    screen-space methods do when they replace non-skin taps by the centre colour.
//  - Absorbs: it leaves the skin. Non-skin samples within r_c facing the receiver's way count in the normaliser
//    Σ K and give no light, so skin next to another material is darker, as in a path tracer, whose random walk
//    ends where the skin's medium ends (docs/pathtraced.md, "Skin next to other materials").
enum class NonSkin { Returns, Absorbs };

struct ConvolutionSettings {
    Transport transport = Transport::ThroughTissue;
    NonSkin nonSkin = NonSkin::Returns;
    double cutoffTail = 1e-3; // share of each channel's energy allowed outside the cutoff radius
    // ThroughTissue: per-channel gain on the sources facing away from the receiver (a thin part's far side), whose
    // light the reflectance profile at the 3-D distance under-estimates against a path tracer (calibration:
    // docs/extensions.md). Does not enter the normaliser. 1: the profile as it is.
    std::array<double, 3> throughGain{1.0, 1.0, 1.0};
    // ThroughTissue: per-channel growth k_c (1/mm²) of that gain with the 3-D distance d (mm) from the far-side
    // source to the receiver: the far side's kernel is R_c(d) · throughGain_c · exp(k_c d²). The reflectance
    // profile's Gaussian tails fall faster with distance than the light a path tracer carries through a slab, so
    // the ratio grows with the thickness of the part; on a sum of Gaussians the factor widens each lobe of variance
    // v to v / (1 − 2 k_c v) (for 2 k_c v < 1). 0: a constant gain, exactly throughGain.
    std::array<double, 3> throughGrowthPerMm2{0.0, 0.0, 0.0};
    // Per-channel length L_c (mm) of the convex-surface gain: the output is multiplied by 1 + L_c κ, κ (1/mm) the
    // surface's curvature at the receiver as its kernel sees it, Σ K · (n_p − n_q)·(p − q) / |p − q|² / Σ K over the
    // facing skin sources (from the smooth normals, so the flat facets of a tessellated mesh do not bias it: exactly
    // 1/R on a sphere of radius R, 0 on a plane, negative where the surface is concave). Light in a
    // convex body reaches the surface again sooner than under a flat one, so a path tracer's skin is brighter there
    // (docs/pathtraced.md, "A convex body's level"). A first-order model of a body thick against the profile: the
    // term fades out where the kernel reaches a thin part's far side (gone at 5 % of the weight there), whose light
    // throughGain carries, and |κ| is clamped to 1 / convexityRadiusMinMm. 0: no gain.
    std::array<double, 3> convexityMm{0.0, 0.0, 0.0};
    // The tightest radius (mm) the convexity gain follows: |κ| is clamped to 1 / convexityRadiusMinMm.
    double convexityRadiusMinMm = 20.0;
    // With convolveSurface's ownShare: sources closer than this (mm) to the receiver belong to its near field with
    // its own term (a coincident twin across a seam, the small triangles of a fan); 0: the own term only. The
    // reference passes half its edge length.
    double nearFieldMm = 0.0;
    unsigned threads = 0; // worker threads; 0: std::thread::hardware_concurrency()
};

struct ConvolutionReport {
    double cutoffRadiusMm = 0.0;
    std::array<double, 3> energyBeyondCutoff{}; // 1 − cumulative(c, r_c) per channel (renormalised away)
    std::size_t receivers = 0;                  // skin samples convolved
    double meanSources = 0.0;                   // mean number of skin sources per receiver
};

// irradiance: per sample, linear RGB (same size as samples). receivers: indices of the samples to convolve (all
// samples when null); skin samples not listed keep E·α. Returns the diffuse radiance E·α after SSS per sample.
//
// ownShare (optional, resized to the samples): the near field split off. The receiver's own term K_c(p, p) — the
// profile's mass over its own disc, the narrow lobes of a skin profile (d'Eon's σ = 80 µm and 0.22 mm) nearly
// whole — and the sources closer than settings.nearFieldMm are then left out of the returned sum and reported as
// their share s_c(p) = Σ_near K_c(p, q) · g_c / Σ_q K_c(p, q) (g_c the convex-surface gain), so that
// out_c(p) ≈ returned_c(p) + s_c(p) · E_c(p) α_c(p) (exact with nearFieldMm = 0). A renderer that has
// E·α at a finer resolution than the samples (the main pass's pixels) multiplies the share by that instead: light
// and colour detail finer than the sample spacing (a shadow's or a light's edge, pores) keeps the sharpness the
// narrow lobes give it, where interpolating the samples' sums would draw it as a staircase of the tessellation.
// Samples that are not convolved get share 1 and return 0.
std::vector<glm::vec3> convolveSurface(const SurfaceSamples& samples, const std::vector<glm::vec3>& irradiance,
                                       const sss::RadialProfile& profile, const ConvolutionSettings& settings = {},
                                       const std::vector<std::uint32_t>* receivers = nullptr,
                                       ConvolutionReport* report = nullptr, std::vector<glm::vec3>* ownShare = nullptr);

} // namespace skinlab::renderer::reference
