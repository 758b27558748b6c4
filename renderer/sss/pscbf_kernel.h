#pragma once
// Mikkelsen's pseudo-separable cross-bilateral filter ("pscbf"): profile and taps (GL-free).
// Source: M. S. Mikkelsen, "Skin Rendering by Pseudo-Separable Cross Bilateral Filtering", Naughty Dog / DTU
// technical report, 2010, Table 1 and §3. docs/extensions.md describes the method.
//
// Profile: a spike (the unblurred irradiance, a Dirac delta) plus one broad 2-D Gaussian per channel,
//   R_c(r) = spike_c · δ(r) + (1 − spike_c) · G(v_c, r),   G(v, r) = exp(−r²/(2v)) / (2πv)
// with spike = 15/18/20 % and v = 2.3/1.4/1.1 for R/G/B. The paper calls v the "variance" in mm units; we read it
// as v in mm² of G above. This reading is consistent with the paper's own filter extent r_max = 4.5 mm, which is
// 3 standard deviations of the red Gaussian (3·√2.3 = 4.55 mm).
//
// Taps: the 2-D Gaussian is separable, so each axis of the two pseudo-separable passes uses the 1-D Gaussian of
// variance v_c truncated to [−r_max, r_max] (the projected disc of radius r_max bounds the filter). N = 13 taps per
// axis sit at equal steps of the red channel's cumulative distribution: cell k is [Q(k/N), Q((k+1)/N)] and the tap
// sits at the cell's median Q((k+½)/N), so every red tap carries probability 1/N. Green and blue are re-weighted on
// the same taps with their own exact energy in each cell (renormalised to 1), as Mikkelsen does.
// The spike is not part of the taps: the method's output is spike_c · centre + (1 − spike_c) · (two-pass blur).
#include "renderer/sss/kernel.h"

#include <array>
#include <nlohmann/json.hpp>
#include <vector>

namespace skinlab::renderer::sss {

// Mikkelsen 2010, Table 1 lists 2.3 / 1.4 / 1.1 for the broad Gaussian and calls the value a "variance" (Eq. 7:
// "variance σ/K and σ"), so the numbers may be the variance v (mm²) or, as the symbol σ suggests, the standard
// deviation (mm). Default: variance, the reading the paper's own filter extent r_max = 4.5 mm supports (3 standard
// deviations of the red Gaussian, 3·√2.3 = 4.55 mm; under the other reading r_max would cut the red Gaussian at 1.96 σ).
// sss.pscbf_sigma (renderer/sss/methods/pscbf.h).
enum class PscbfSigma {
    Variance, // v_c = 2.3 / 1.4 / 1.1 mm²
    StdDev,   // σ_c = 2.3 / 1.4 / 1.1 mm, v_c = σ_c²
};
NLOHMANN_JSON_SERIALIZE_ENUM(PscbfSigma, {{PscbfSigma::Variance, "variance"}, {PscbfSigma::StdDev, "std-dev"}})

struct PscbfProfile {
    std::array<double, 3> spike;       // share of the unblurred irradiance per channel (R, G, B), in [0, 1)
    std::array<double, 3> varianceMm2; // v_c of the broad Gaussian, mm²
    double maxRadiusMm;                // r_max: radius of the filter disc on the surface, mm
};

// Mikkelsen 2010, Table 1, for skin: spike (0.15, 0.18, 0.20), r_max 4.5 mm, and 2.3 / 1.4 / 1.1 read as the
// variance v in mm² (PscbfSigma::Variance, the default) or as the standard deviation in mm (v = 5.29 / 1.96 / 1.21).
const PscbfProfile& mikkelsenSkinProfile(PscbfSigma reading = PscbfSigma::Variance);
inline constexpr int kPscbfSamples = 13; // taps per axis in the paper

// The broad part's radial density G(v_c, r) in 1/mm² (unit integral; the spike excluded).
double pscbfBroadRadial(const PscbfProfile& profile, int channel, double rMm);
// Cumulative of the broad part's 1-D marginal truncated to [−r_max, r_max] (0 below −r_max, 1 above r_max).
double pscbfTruncatedCumulative(const PscbfProfile& profile, int channel, double xMm);

struct PscbfKernel {
    PscbfProfile profile;
    std::vector<KernelTap> taps; // one axis, ascending offsets in mm, symmetric, each channel sums to 1

    // The broad part as one stage of kernel.h (accumulate = 1 − spike), so that cpu_blur's passes can run it.
    KernelStage broadStage() const;
    nlohmann::json toJson() const;
};

// Builds the taps (samples odd, 3…101; the paper uses 13). Asserts a valid profile.
PscbfKernel makePscbfKernel(const PscbfProfile& profile = mikkelsenSkinProfile(), int samples = kPscbfSamples);

} // namespace skinlab::renderer::sss
