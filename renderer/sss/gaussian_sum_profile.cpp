#include "renderer/sss/gaussian_sum_profile.h"

#include "common/check.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace skinlab::renderer::sss {

const std::vector<GaussianLobe>& deonSkinLobes() {
    // GPU Gems 3 ch. 14, Table 14-1 (variances in mm², weights R, G, B).
    static const std::vector<GaussianLobe> lobes{
        {0.0064, {0.233, 0.455, 0.649}}, {0.0484, {0.100, 0.336, 0.344}}, {0.187, {0.118, 0.198, 0.0}},
        {0.567, {0.113, 0.007, 0.007}},  {1.99, {0.358, 0.004, 0.0}},     {7.41, {0.078, 0.0, 0.0}},
    };
    return lobes;
}

double gaussian2d(double varianceMm2, double rMm) {
    return std::exp(-rMm * rMm / (2.0 * varianceMm2)) / (2.0 * std::numbers::pi * varianceMm2);
}

double gaussian1d(double varianceMm2, double xMm) {
    return std::exp(-xMm * xMm / (2.0 * varianceMm2)) / std::sqrt(2.0 * std::numbers::pi * varianceMm2);
}

std::array<double, 3> deonTransmittance(double thicknessMm) {
    std::array<double, 3> t{0.0, 0.0, 0.0};
    const double s2 = thicknessMm * thicknessMm;
    for (const auto& lobe : deonSkinLobes())
        for (int c = 0; c < 3; ++c) t[c] += lobe.weight[c] * std::exp(-s2 / lobe.varianceMm2);
    return t;
}

GaussianSumProfile::GaussianSumProfile(std::vector<GaussianLobe> lobes, std::string description)
    : lobes_(std::move(lobes)), description_(std::move(description)) {
    std::sort(lobes_.begin(), lobes_.end(),
              [](const GaussianLobe& a, const GaussianLobe& b) { return a.varianceMm2 < b.varianceMm2; });
    for (const auto& lobe : lobes_) {
        SKINLAB_CHECK_GT(lobe.varianceMm2, 0.0);
        for (int c = 0; c < 3; ++c) totals_[c] += lobe.weight[c];
    }
    for (int c = 0; c < 3; ++c) SKINLAB_CHECK_GT(totals_[c], 0.0);
}

double GaussianSumProfile::radial(int channel, double rMm) const {
    double sum = 0.0;
    for (const auto& lobe : lobes_) sum += lobe.weight[channel] * gaussian2d(lobe.varianceMm2, rMm);
    return sum / totals_[channel];
}

double GaussianSumProfile::density(int channel, double xMm) const {
    double sum = 0.0;
    for (const auto& lobe : lobes_) sum += lobe.weight[channel] * gaussian1d(lobe.varianceMm2, xMm);
    return sum / totals_[channel];
}

double GaussianSumProfile::cumulative(int channel, double xMm) const {
    double sum = 0.0;
    for (const auto& lobe : lobes_)
        sum += lobe.weight[channel] * 0.5 * std::erfc(-xMm / std::sqrt(2.0 * lobe.varianceMm2));
    return sum / totals_[channel];
}

double GaussianSumProfile::secondMoment(int channel) const {
    // The 1-D marginal of a 2-D Gaussian of variance v is a 1-D Gaussian of variance v.
    double sum = 0.0;
    for (const auto& lobe : lobes_) sum += lobe.weight[channel] * lobe.varianceMm2;
    return sum / totals_[channel];
}

double GaussianSumProfile::searchRadiusMm() const {
    // 7 standard deviations of the widest lobe: tail below 1e-11.
    return 7.0 * std::sqrt(lobes_.back().varianceMm2);
}

} // namespace skinlab::renderer::sss
