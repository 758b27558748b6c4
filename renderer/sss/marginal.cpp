#include "renderer/sss/marginal.h"

#include <algorithm>

namespace skinlab::renderer::sss {

double Marginal::tailEnergy(int channel, double xMm) const {
    return std::max(0.0, 2.0 * (1.0 - cumulative(channel, std::abs(xMm))));
}

double Marginal::truncationRadiusMm(double tail) const {
    double lo = 0.0;
    double hi = searchRadiusMm();
    auto ok = [&](double x) {
        for (int c = 0; c < kChannels; ++c)
            if (tailEnergy(c, x) > tail) return false;
        return true;
    };
    // 60 halvings: far below any pixel footprint.
    for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (ok(mid) ? hi : lo) = mid;
    }
    return hi;
}

double Marginal::quantile(int channel, double probability) const {
    double lo = -searchRadiusMm();
    double hi = searchRadiusMm();
    for (int i = 0; i < 80; ++i) {
        const double mid = 0.5 * (lo + hi);
        (cumulative(channel, mid) < probability ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

int Marginal::widestChannel() const {
    int widest = 0;
    for (int c = 1; c < kChannels; ++c)
        if (secondMoment(c) > secondMoment(widest)) widest = c;
    return widest;
}

} // namespace skinlab::renderer::sss
