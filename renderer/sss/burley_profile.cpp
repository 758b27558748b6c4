#include "renderer/sss/burley_profile.h"

#include "common/check.h"
#include "renderer/sss/radial_marginal.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace skinlab::renderer::sss {

BurleyProfile::BurleyProfile(std::array<double, 3> shapeMm, std::string description)
    : d_(shapeMm), description_(std::move(description)) {
    for (double d : d_) {
        SKINLAB_CHECK_GT(d, 0.0);
        (void)d;
    }
}

double BurleyProfile::radial(int channel, double rMm) const {
    const double d = d_[channel];
    const double r = std::max(rMm, 1e-300);
    return (std::exp(-r / d) + std::exp(-r / (3.0 * d))) / (8.0 * std::numbers::pi * d * r);
}

double BurleyProfile::radialCumulative(int channel, double rMm) const {
    const double d = d_[channel];
    return 1.0 - 0.25 * std::exp(-rMm / d) - 0.75 * std::exp(-rMm / (3.0 * d));
}

double BurleyProfile::densityNumerical(int channel, double xMm) const {
    return marginalOfRadial([&](double r) { return radial(channel, r); }, xMm, 3.0 * d_[channel]);
}

double BurleyProfile::density(int channel, double xMm) const {
    const double x = std::abs(xMm);
    if (x == 0.0) return std::numeric_limits<double>::infinity();
    const double d = d_[channel];
    return (std::cyl_bessel_k(0.0, x / d) + std::cyl_bessel_k(0.0, x / (3.0 * d))) / (4.0 * std::numbers::pi * d);
}

namespace {
// F(z) = ∫_0^z K0(u) du, tabulated once on nodes z_k = zMax (k/M)² (dense where K0 has its log singularity) by
// 5-point Gauss-Legendre per interval and read back by cubic Hermite interpolation with the exact derivative
// F' = K0 (interpolation error < 1e-9). Burley's marginal CDF is then closed form in F (see cumulative()).
class BesselK0Integral {
public:
    BesselK0Integral() : values_(kNodes + 1) {
        values_[0] = 0.0;
        values_[1] = series(node(1));
        // Gauss-Legendre abscissae and weights on [−1, 1].
        const double x[5] = {0.0, -0.5384693101056831, 0.5384693101056831, -0.9061798459386640, 0.9061798459386640};
        const double w[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665, 0.2369268850561891,
                             0.2369268850561891};
        for (int k = 1; k < kNodes; ++k) {
            const double a = node(k), b = node(k + 1);
            double sum = 0.0;
            for (int i = 0; i < 5; ++i) sum += w[i] * std::cyl_bessel_k(0.0, 0.5 * (a + b) + 0.5 * (b - a) * x[i]);
            values_[k + 1] = values_[k] + 0.5 * (b - a) * sum;
        }
    }
    double operator()(double z) const {
        if (z <= 0.0) return 0.0;
        if (z >= kMax) return std::numbers::pi / 2.0; // K0(100) ≈ 5e-45: the rest of the integral is nil
        if (z < node(1)) return series(z);
        const int k = std::min(kNodes - 1, static_cast<int>(kNodes * std::sqrt(z / kMax)));
        const double a = node(k), b = node(k + 1), h = b - a, t = (z - a) / h;
        const double da = std::cyl_bessel_k(0.0, a) * h, db = std::cyl_bessel_k(0.0, b) * h;
        const double t2 = t * t, t3 = t2 * t;
        return (2 * t3 - 3 * t2 + 1) * values_[k] + (t3 - 2 * t2 + t) * da + (-2 * t3 + 3 * t2) * values_[k + 1] +
               (t3 - t2) * db;
    }

private:
    static constexpr int kNodes = 4000;
    static constexpr double kMax = 100.0;
    static double node(int k) { return kMax * double(k) * double(k) / (double(kNodes) * kNodes); }
    // Small-argument series: ∫_0^z K0 = z (1 − γ − ln(z/2)) + O(z³ ln z); used below z_1 = 6.25e-6 only.
    static double series(double z) { return z * (1.0 - std::numbers::egamma - std::log(0.5 * z)); }
    std::vector<double> values_;
};

const BesselK0Integral& besselK0Integral() {
    static const BesselK0Integral table;
    return table;
}
} // namespace

double BurleyProfile::cumulative(int channel, double xMm) const {
    // ∫_0^x a = [d F(x/d) + 3d F(x/(3d))] / (4π d) = [F(x/d) + 3 F(x/(3d))] / (4π), F(∞) = π/2.
    const double d = d_[channel];
    const double x = std::abs(xMm);
    const auto& F = besselK0Integral();
    const double inside = (F(x / d) + 3.0 * F(x / (3.0 * d))) / (4.0 * std::numbers::pi);
    return xMm >= 0.0 ? 0.5 + inside : 0.5 - inside;
}

double BurleyProfile::cumulativeByStrip(int channel, double xMm) const {
    const double d = d_[channel];
    auto cdf = [&](double r) { return radialCumulative(channel, r); };
    // ρ(r) = 2πr R(r) = (e^{−r/d} + e^{−r/(3d)}) / (4d)
    auto rho = [&](double r) { return (std::exp(-r / d) + std::exp(-r / (3.0 * d))) / (4.0 * d); };
    const double inside = stripEnergy(cdf, rho, xMm, 3.0 * d);
    return xMm >= 0.0 ? 0.5 + 0.5 * inside : 0.5 - 0.5 * inside;
}

double BurleyProfile::secondMoment(int channel) const { return 7.0 * d_[channel] * d_[channel]; }

double BurleyProfile::searchRadiusMm() const {
    // e^{−r/(3d)} < 1e-12 beyond 3d·ln(1e12) ≈ 83 d.
    double widest = std::max({d_[0], d_[1], d_[2]});
    return 83.0 * widest;
}

double burleyTransmittance(double shapeMm, double thicknessMm) {
    return 0.25 * (std::exp(-thicknessMm / shapeMm) + 3.0 * std::exp(-thicknessMm / (3.0 * shapeMm)));
}

} // namespace skinlab::renderer::sss
