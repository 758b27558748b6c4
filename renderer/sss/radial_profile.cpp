#include "renderer/sss/radial_profile.h"

#include "common/error.h"
#include "renderer/sss/burley_profile.h"
#include "renderer/sss/gaussian_sum_profile.h"
#include "renderer/sss/materials.h"
#include "renderer/sss/skin_model.h"

#include <algorithm>
#include <cmath>

namespace skinlab::renderer::sss {

namespace {
// d'Eon's sum of Gaussians: the radial CDF of G(v, ·) is 1 − exp(−r²/(2v)).
class GaussianSumRadial final : public RadialProfile {
public:
    GaussianSumRadial(std::vector<GaussianLobe> lobes, double scale)
        : profile_(std::move(lobes), "d'Eon six-Gaussian skin profile"), scale_(scale) {
        for (const auto& lobe : profile_.lobes())
            for (int c = 0; c < 3; ++c) totals_[c] += lobe.weight[c];
    }
    std::string description() const override { return profile_.description(); }
    double radial(int channel, double rMm) const override {
        return scale_ * scale_ * profile_.radial(channel, scale_ * rMm);
    }
    double cumulative(int channel, double rMm) const override {
        const double r = scale_ * rMm;
        double sum = 0.0;
        for (const auto& lobe : profile_.lobes())
            sum += lobe.weight[channel] * -std::expm1(-r * r / (2.0 * lobe.varianceMm2));
        return sum / totals_[channel];
    }

private:
    GaussianSumProfile profile_;
    std::array<double, 3> totals_{};
    double scale_;
};

class BurleyRadial final : public RadialProfile {
public:
    BurleyRadial(const std::array<double, 3>& shapeMm, const std::string& material, double scale)
        : profile_(shapeMm, "Burley normalized diffusion, material " + material), scale_(scale) {}
    std::string description() const override { return profile_.description(); }
    double radial(int channel, double rMm) const override {
        return scale_ * scale_ * profile_.radial(channel, scale_ * rMm);
    }
    double cumulative(int channel, double rMm) const override {
        return profile_.radialCumulative(channel, scale_ * rMm);
    }

private:
    BurleyProfile profile_;
    double scale_;
};
} // namespace

double RadialProfile::cutoffRadiusMm(double tail) const {
    double high = 1.0;
    const auto outside = [&](double r) {
        double worst = 0.0;
        for (int c = 0; c < 3; ++c) worst = std::max(worst, 1.0 - cumulative(c, r));
        return worst;
    };
    while (outside(high) > tail && high < 1e6) high *= 2.0;
    double low = 0.0;
    for (int i = 0; i < 100; ++i) {
        const double middle = 0.5 * (low + high);
        if (outside(middle) > tail) low = middle;
        else high = middle;
    }
    return high;
}

std::unique_ptr<RadialProfile> makeRadialProfile(const SssParams& params) {
    if (!(params.widthMm > 0.0)) throwInput("", "sss.width_mm", "must be positive");
    // Surface distance d (mm) ↔ profile distance d / profileScale(width_mm) (renderer/sss/sss_params.h).
    const double scale = kProfileWidthMm / params.widthMm; // 1 / profileScale, as one division
    if (params.profile == "deon") return std::make_unique<GaussianSumRadial>(skinProfileLobes(params), scale);
    if (params.profile == "burley")
        return std::make_unique<BurleyRadial>(skinBurleyShapeMm(params), params.material, scale);
    throwInput("", "sss.profile",
               "'" + params.profile + "' has no radial form for the reference method (use deon or burley)");
}

} // namespace skinlab::renderer::sss
