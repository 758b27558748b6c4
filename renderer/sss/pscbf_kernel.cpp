#include "renderer/sss/pscbf_kernel.h"

#include "common/check.h"
#include "renderer/sss/discretisation.h"
#include "renderer/sss/gaussian_sum_profile.h"

#include <cmath>

namespace skinlab::renderer::sss {

namespace {
// Standard normal cumulative of x/σ.
double normalCumulative(double xMm, double varianceMm2) { return 0.5 * std::erfc(-xMm / std::sqrt(2.0 * varianceMm2)); }

// Inverse of pscbfTruncatedCumulative for one channel by bisection (monotone on [−r_max, r_max]); 200 halvings
// reach double precision long before the loop ends, so the result does not depend on a tolerance.
double truncatedQuantile(const PscbfProfile& profile, int channel, double probability) {
    double low = -profile.maxRadiusMm;
    double high = profile.maxRadiusMm;
    for (int i = 0; i < 200 && high - low > 0.0; ++i) {
        const double middle = 0.5 * (low + high);
        if (middle == low || middle == high) break;
        if (pscbfTruncatedCumulative(profile, channel, middle) < probability) low = middle;
        else high = middle;
    }
    return 0.5 * (low + high);
}
} // namespace

const PscbfProfile& mikkelsenSkinProfile(PscbfSigma reading) {
    static const PscbfProfile variance{{0.15, 0.18, 0.20}, {2.3, 1.4, 1.1}, 4.5};
    static const PscbfProfile standardDeviation{{0.15, 0.18, 0.20}, {2.3 * 2.3, 1.4 * 1.4, 1.1 * 1.1}, 4.5};
    return reading == PscbfSigma::StdDev ? standardDeviation : variance;
}

double pscbfBroadRadial(const PscbfProfile& profile, int channel, double rMm) {
    return gaussian2d(profile.varianceMm2[channel], rMm);
}

double pscbfTruncatedCumulative(const PscbfProfile& profile, int channel, double xMm) {
    const double r = profile.maxRadiusMm;
    if (xMm <= -r) return 0.0;
    if (xMm >= r) return 1.0;
    const double v = profile.varianceMm2[channel];
    const double low = normalCumulative(-r, v);
    const double high = normalCumulative(r, v);
    return (normalCumulative(xMm, v) - low) / (high - low);
}

PscbfKernel makePscbfKernel(const PscbfProfile& profile, int samples) {
    SKINLAB_CHECK_GE(samples, 3);
    SKINLAB_CHECK_LE(samples, 101);
    SKINLAB_CHECK_EQ(samples % 2, 1);
    SKINLAB_CHECK_GT(profile.maxRadiusMm, 0.0);
    for (int c = 0; c < kChannels; ++c) {
        SKINLAB_CHECK_GT(profile.varianceMm2[c], 0.0);
        SKINLAB_CHECK_GE(profile.spike[c], 0.0);
        SKINLAB_CHECK_LT(profile.spike[c], 1.0);
    }
    constexpr int red = 0; // Mikkelsen places the taps on the red (widest) channel's distribution
    const int half = samples / 2;
    std::vector<double> bounds(static_cast<size_t>(samples) + 1);
    bounds.front() = -profile.maxRadiusMm;
    bounds.back() = profile.maxRadiusMm;
    // Symmetric by construction: the right half is computed and mirrored, the centre tap sits exactly at 0.
    for (int k = half + 1; k < samples; ++k) {
        bounds[k] = truncatedQuantile(profile, red, double(k) / samples);
        bounds[samples - k] = -bounds[k];
    }
    PscbfKernel kernel{profile, std::vector<KernelTap>(static_cast<size_t>(samples))};
    kernel.taps[half].offsetMm = 0.0;
    for (int k = half + 1; k < samples; ++k) {
        kernel.taps[k].offsetMm = truncatedQuantile(profile, red, (k + 0.5) / samples);
        kernel.taps[samples - 1 - k].offsetMm = -kernel.taps[k].offsetMm;
    }
    // Right half (centre included), mirrored: the weights are exactly symmetric.
    for (int k = half; k < samples; ++k)
        for (int c = 0; c < kChannels; ++c) {
            kernel.taps[k].weight[c] =
                pscbfTruncatedCumulative(profile, c, bounds[k + 1]) - pscbfTruncatedCumulative(profile, c, bounds[k]);
            kernel.taps[samples - 1 - k].weight[c] = kernel.taps[k].weight[c];
        }
    normaliseChannels(kernel.taps);
    return kernel;
}

KernelStage PscbfKernel::broadStage() const {
    KernelStage stage;
    stage.taps = taps;
    for (int c = 0; c < kChannels; ++c) stage.accumulate[c] = 1.0 - profile.spike[c];
    return stage;
}

nlohmann::json PscbfKernel::toJson() const {
    nlohmann::json tapList = nlohmann::json::array();
    for (const auto& tap : taps) tapList.push_back({{"offset_mm", tap.offsetMm}, {"weight", tap.weight}});
    return {{"method", "pscbf"},
            {"source", "Mikkelsen 2010 spike + one Gaussian per channel, taps at equal steps of the red CDF"},
            {"spike", profile.spike},
            {"variance_mm2", profile.varianceMm2},
            {"max_radius_mm", profile.maxRadiusMm},
            {"taps", tapList}};
}

} // namespace skinlab::renderer::sss
