#pragma once
// Sum-of-Gaussians diffusion profile R(r) = Σ w_i G(v_i, r), G(v, r) = exp(−r²/(2v)) / (2πv) (unit integral over the
// plane; v in mm²). Its marginal is exact: ∫ G(v, √(x²+y²)) dy = exp(−x²/(2v)) / √(2πv) (d'Eon & Luebke, GPU Gems 3 ch. 14).
// d'Eon & Luebke, "Advanced Techniques for Realistic Real-Time Skin Rendering", GPU Gems 3 ch. 14, 2007, Table 14-1.
#include "renderer/sss/marginal.h"

#include <array>
#include <vector>

namespace skinlab::renderer::sss {

struct GaussianLobe {
    double varianceMm2;           // v_i, mm²
    std::array<double, 3> weight; // w_i per channel (R, G, B)
};

// d'Eon's six lobes for skin, ascending variance; each channel's weights sum to 1 (blue 0.649, the published value).
const std::vector<GaussianLobe>& deonSkinLobes();

// 2-D Gaussian with unit integral, 1/mm².
double gaussian2d(double varianceMm2, double rMm);
// 1-D Gaussian with unit integral, 1/mm (the marginal of gaussian2d).
double gaussian1d(double varianceMm2, double xMm);

// Transmittance through a slab of scaled thickness s (mm) with d'Eon's weights, T(s) = Σ w_i exp(−s²/v_i)
// (Jimenez et al., IEEE CG&A 2010); T(0) = 1 per channel.
std::array<double, 3> deonTransmittance(double thicknessMm);

class GaussianSumProfile final : public Marginal {
public:
    // `lobes` in any order; weights need not be normalised (the profile is normalised per channel).
    GaussianSumProfile(std::vector<GaussianLobe> lobes, std::string description);

    const std::vector<GaussianLobe>& lobes() const { return lobes_; }
    // R_c(r), 1/mm².
    double radial(int channel, double rMm) const;

    std::string description() const override { return description_; }
    double density(int channel, double xMm) const override;
    double cumulative(int channel, double xMm) const override;
    double secondMoment(int channel) const override;
    double searchRadiusMm() const override;

private:
    std::vector<GaussianLobe> lobes_;
    std::array<double, 3> totals_{};
    std::string description_;
};

} // namespace skinlab::renderer::sss
