#include "renderer/sss/discretisation.h"

#include "common/check.h"

#include <cmath>

namespace skinlab::renderer::sss {

void normaliseChannels(std::vector<KernelTap>& taps) {
    for (int c = 0; c < kChannels; ++c) {
        double sum = 0.0;
        for (const auto& tap : taps) sum += tap.weight[c];
        SKINLAB_CHECK_GT(sum, 0.0);
        for (auto& tap : taps) tap.weight[c] /= sum;
    }
}

std::vector<KernelTap> quadraticTaps(const Marginal& marginal, int samples) {
    SKINLAB_CHECK_GE(samples, 3);
    SKINLAB_CHECK_EQ(samples % 2, 1);
    const double range = marginal.truncationRadiusMm(kTruncatedTail);
    std::vector<KernelTap> taps(static_cast<size_t>(samples));
    const int half = samples / 2;
    for (int i = 0; i < samples; ++i) {
        const double t = double(i - half) / double(half); // [−1, 1]
        taps[i].offsetMm = range * (t < 0 ? -1.0 : 1.0) * t * t;
    }
    for (int i = 0; i < samples; ++i) {
        const double o = taps[i].offsetMm;
        const double left = i > 0 ? std::abs(o - taps[i - 1].offsetMm) : 0.0;
        const double right = i + 1 < samples ? std::abs(o - taps[i + 1].offsetMm) : 0.0;
        const double area = 0.5 * (left + right);
        for (int c = 0; c < kChannels; ++c) {
            const double a = marginal.density(c, o);
            taps[i].weight[c] = std::isfinite(a)
                                    ? a * area
                                    : marginal.cumulative(c, o + 0.5 * right) - marginal.cumulative(c, o - 0.5 * left);
        }
    }
    normaliseChannels(taps);
    return taps;
}

std::vector<KernelTap> importanceTaps(const Marginal& marginal, int samples) {
    SKINLAB_CHECK_GE(samples, 3);
    SKINLAB_CHECK_EQ(samples % 2, 1);
    const int widest = marginal.widestChannel();
    std::vector<double> bounds(static_cast<size_t>(samples) + 1);
    const double far = marginal.searchRadiusMm();
    bounds.front() = -far;
    bounds.back() = far;
    const int half = samples / 2;
    // Symmetric by construction: compute the right half and mirror, so the centre tap sits exactly at 0.
    for (int k = half + 1; k < samples; ++k) {
        bounds[k] = marginal.quantile(widest, double(k) / samples);
        bounds[samples - k] = -bounds[k];
    }
    std::vector<KernelTap> taps(static_cast<size_t>(samples));
    taps[half].offsetMm = 0.0; // the median of the centre cell of a symmetric density
    for (int k = half + 1; k < samples; ++k) {
        taps[k].offsetMm = marginal.quantile(widest, (k + 0.5) / samples);
        taps[samples - 1 - k].offsetMm = -taps[k].offsetMm;
    }
    for (int k = 0; k < samples; ++k)
        for (int c = 0; c < kChannels; ++c)
            taps[k].weight[c] = marginal.cumulative(c, bounds[k + 1]) - marginal.cumulative(c, bounds[k]);
    normaliseChannels(taps);
    return taps;
}

std::vector<KernelTap> discretise(const Marginal& marginal, int samples, TapPlacement placement) {
    return placement == TapPlacement::Quadratic ? quadraticTaps(marginal, samples) : importanceTaps(marginal, samples);
}

} // namespace skinlab::renderer::sss
