#pragma once
// The object-space reference SSS : convolution of per-sample diffuse irradiance × albedo over the
// surface with a radial diffusion profile at true 3-D distances, among skin samples only.
//
// For a skin receiver p and skin sources q within the cutoff radius r_c (3-D distance |p − q| in mm):
//   K_c(p, q) = R_c(|p − q|) · A_q                    (q ≠ p; A_q: the source's area, mm²)
//   K_c(p, p) = ∫_0^a 2πs R_c(s) ds,  a = √(A_p / π)  (the receiver's own disc: exact for the narrow lobes that
//                                                      fall between samples, and finite for Burley's 1/r centre)
//   out_c(p)  = Σ_q K_c(p, q) E_c(q) α_c(q) / Σ_q K_c(p, q)
// E: irradiance, α: albedo. Non-skin samples neither scatter (they are never sources) nor receive (their output is
// E·α, unblurred). Dividing by Σ K keeps a uniformly lit, uniformly coloured skin surface unchanged and hands the
// energy of the tails beyond r_c, of non-skin neighbours and of the quadrature error back to the receiver, as the
// screen-space methods do when they replace non-skin taps by the centre colour (renderer/sss/cpu_blur.h).
//
// r_c is the radius outside which every channel of the profile has at most `cutoffTail` of its energy
// (default 1e-3, 0.1 %: 8.0 mm for d'Eon's skin profile at width 3 mm).
#include "renderer/reference/radial_profile.h"
#include "renderer/reference/surface_samples.h"

#include <array>
#include <cstdint>
#include <vector>

namespace skinlab::renderer::reference {

struct ConvolutionSettings {
    double cutoffTail = 1e-3;  // share of each channel's energy allowed outside the cutoff radius
    unsigned threads = 0;      // worker threads; 0: std::thread::hardware_concurrency()
};

struct ConvolutionReport {
    double cutoffRadiusMm = 0.0;
    std::array<double, 3> energyBeyondCutoff{};  // 1 − cumulative(c, r_c) per channel (renormalised away)
    std::size_t receivers = 0;                   // skin samples convolved
    double meanSources = 0.0;                    // mean number of skin sources per receiver
};

// irradiance: per sample, linear RGB (same size as samples). receivers: indices of the samples to convolve (all
// samples when null); skin samples not listed keep E·α. Returns the diffuse radiance E·α after SSS per sample.
std::vector<glm::vec3> convolveSurface(const SurfaceSamples& samples, const std::vector<glm::vec3>& irradiance,
                                       const RadialProfile& profile, const ConvolutionSettings& settings = {},
                                       const std::vector<std::uint32_t>* receivers = nullptr,
                                       ConvolutionReport* report = nullptr);

} // namespace skinlab::renderer::reference
