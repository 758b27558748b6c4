#include "renderer/sss/artistic_kernel.h"

#include "common/check.h"
#include "renderer/sss/discretisation.h"
#include "renderer/sss/gaussian_sum_profile.h"

#include <cmath>

namespace skinlab::renderer::sss {

namespace {
// The demo's profile: d'Eon's red lobes 2…6 with the radius divided by (0.001 + falloff) per channel.
double artisticProfile(double r, double falloff) {
    const double rr = r / (0.001 + falloff);
    const auto& lobes = deonSkinLobes();
    double sum = 0.0;
    for (size_t i = 1; i < lobes.size(); ++i) sum += lobes[i].weight[0] * gaussian2d(lobes[i].varianceMm2, rr);
    return sum;
}
} // namespace

std::vector<KernelTap> artisticTaps(int samples, const std::array<double, 3>& strength,
                                    const std::array<double, 3>& falloff) {
    SKINLAB_CHECK_GE(samples, 3);
    SKINLAB_CHECK_EQ(samples % 2, 1);
    const double range = samples > 20 ? 3.0 : 2.0;
    const double step = 2.0 * range / double(samples - 1);
    std::vector<KernelTap> taps(static_cast<size_t>(samples));
    const int half = samples / 2;
    for (int i = 0; i < samples; ++i) {
        // t computed from the centre so that the centre tap is exactly 0 and the kernel exactly symmetric.
        const double t = double(i - half) * step;
        taps[i].offsetMm = range * (t < 0 ? -1.0 : 1.0) * t * t / (range * range);
    }
    for (int i = 0; i < samples; ++i) {
        const double o = taps[i].offsetMm;
        const double left = i > 0 ? std::abs(o - taps[i - 1].offsetMm) : 0.0;
        const double right = i + 1 < samples ? std::abs(o - taps[i + 1].offsetMm) : 0.0;
        const double area = 0.5 * (left + right);
        for (int c = 0; c < 3; ++c) taps[i].weight[c] = area * artisticProfile(o, falloff[c]);
    }
    normaliseChannels(taps);
    for (int i = 0; i < samples; ++i)
        for (int c = 0; c < 3; ++c)
            taps[i].weight[c] =
                i == half ? (1.0 - strength[c]) + strength[c] * taps[i].weight[c] : strength[c] * taps[i].weight[c];
    return taps;
}

} // namespace skinlab::renderer::sss
