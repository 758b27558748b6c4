#pragma once
// The SSS kernel actually used by a method: one or more 1-D stages of taps, each tap an offset in millimetres on the
// surface and an RGB weight. A stage is applied as a horizontal then a vertical pass. Stage i blurs the result of
// stage i−1 (stage 0 blurs the input), and the method's output is Σ_i accumulate_i · stage_i (per channel):
//  - separable, artistic: one stage, accumulate = (1, 1, 1);
//  - gaussian-sum: six stages, stage i a Gaussian of variance v_i − v_{i−1} (so stage i has total variance v_i,
//    Jimenez & Gutierrez 2010), accumulate_i = d'Eon's weights w_i.
// Weights of every stage sum to 1 per channel, and Σ_i accumulate_i = 1 per channel, so a flat image is unchanged.
#include "renderer/sss/marginal.h"
#include "renderer/sss/sss_params.h"

#include <array>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace skinlab::renderer::sss {

struct KernelTap {
    double offsetMm;              // signed offset on the surface, mm
    std::array<double, 3> weight; // R, G, B
};

struct KernelStage {
    std::vector<KernelTap> taps;      // ascending offsets, symmetric, odd count, centre tap at offset 0
    std::array<double, 3> accumulate; // weight of this stage's result in the output, per channel
    double varianceMm2 = 0.0;         // gaussian-sum: variance of this stage's own Gaussian; 0 otherwise
};

struct Kernel {
    SssMethod method{}; // "none"
    std::string source; // what the taps were computed from, e.g. "d'Eon six-Gaussian skin profile (marginal)"
    std::vector<KernelStage> stages;

    // Support radius on the surface, mm (EXR attribute skinlab:sss_radius_mm): the largest tap offset; for cascaded
    // stages the root sum of squares of the stages' reaches (exact for Gaussians).
    double supportRadiusMm() const;
    nlohmann::json toJson() const;
    // Set where the method's filter reaches further than its outermost tap (pscbf: the disc of radius r_max that
    // bounds the filter, 4.5 mm × width_mm / 3, while its 13 taps sit at cell medians inside it); 0: from the taps.
    double declaredSupportMm = 0.0;
};

// Share of a discretised channel's energy the taps leave outside the truncation radius of quadratic placement
// (the remainder is renormalised into the taps): 0.2 %.
constexpr double kTruncatedTail = 0.002;

// Multiplies every tap's offset by `scale` (profile millimetres → surface millimetres: profileScale(width_mm)).
void scaleOffsets(std::vector<KernelTap>& taps, double scale);

// Builds the kernel of `params` through its method's class (method.h) (throws InputError for inconsistent parameters, e.g. an unreadable file: profile,
// or a material without a d'Eon profile). Method "none" gives an empty kernel.
Kernel makeKernel(const SssParams& params);

// The continuous 1-D marginal behind the separable method (profile + material, or a file: kernel), in profile
// millimetres (before the width_mm / 3 scale). InputError for an unreadable file or a material without a profile.
std::unique_ptr<Marginal> makeMarginal(const SssParams& params);

// Per-channel statistics of one stage's taps: RMS width √(Σ w x² / Σ w) (mm) and the share of weight at |x| > tail.
struct KernelStatistics {
    std::array<double, 3> rmsWidthMm;
    std::array<double, 3> energyBeyond;
};
KernelStatistics tapStatistics(const std::vector<KernelTap>& taps, double beyondMm);

} // namespace skinlab::renderer::sss
