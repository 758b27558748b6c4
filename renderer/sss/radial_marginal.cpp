#include "renderer/sss/radial_marginal.h"

#include "renderer/sss/numerical_integration.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace skinlab::renderer::sss {

double marginalOfRadial(const std::function<double(double)>& radial, double xMm, double scaleMm) {
    const double x = std::abs(xMm);
    auto integrand = [&](double u) { return radial(std::sqrt(x * x + u * u)); };
    // Near u = 0 the integrand varies on the scale of x (it peaks like 1/√(x²+u²) for profiles with a 1/r core),
    // so integrate [0, x] separately from the exponential tail.
    const double near = x > 0.0 ? integrate(integrand, 0.0, std::min(x, scaleMm), 1e-12) : 0.0;
    const double start = x > 0.0 ? std::min(x, scaleMm) : 0.0;
    return 2.0 * (near + integrateToInfinity(integrand, start, scaleMm, 1e-12));
}

double stripEnergy(const std::function<double(double)>& radialCdf, const std::function<double(double)>& radialDensity,
                   double halfWidthMm, double scaleMm) {
    const double X = std::abs(halfWidthMm);
    if (X == 0.0) return 0.0;
    auto outside = [&](double r) {
        return radialDensity(r) * (2.0 / std::numbers::pi) * std::asin(std::min(1.0, X / r));
    };
    return radialCdf(X) + integrateToInfinity(outside, X, scaleMm, 1e-12);
}

} // namespace skinlab::renderer::sss
