#pragma once
// Adaptive Simpson quadrature (Lyness 1969) for the smooth 1-D integrals of the kernel module: marginals of
// radial profiles that have no closed form, their cumulative distributions and moments. Double precision; the
// tolerance is absolute.
#include <functional>

namespace skinlab::renderer::sss {

// ∫_a^b f(x) dx with adaptive Simpson subdivision to |error| ≲ tolerance (depth-limited).
double integrate(const std::function<double(double)>& f, double a, double b, double tolerance = 1e-10);

// ∫_a^∞ f(x) dx for f decaying at least exponentially on the length scale `scale` (> 0): the half-line is split
// into [a, a+scale·2^k] pieces until a piece contributes less than the tolerance.
double integrateToInfinity(const std::function<double(double)>& f, double a, double scale, double tolerance = 1e-10);

} // namespace skinlab::renderer::sss
