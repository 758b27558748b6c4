#pragma once
// Numerical 1-D marginal of any radial profile (d'Eon & Luebke, GPU Gems 3 ch. 14): a(x) = ∫ R(√(x²+y²)) dy = 2 ∫_0^∞ R(√(x²+u²)) du.
// Used for profiles without a closed form and to check the closed forms (Gaussian, Burley/K0) in tests.
#include <functional>

namespace skinlab::renderer::sss {

// `radial`: R(r) in 1/mm² for r ≥ 0; `scaleMm`: a length on which R decays (sets the integration pieces).
double marginalOfRadial(const std::function<double(double)>& radial, double xMm, double scaleMm);

// Energy of a radial profile inside the strip |x| ≤ X: ∫_0^∞ ρ(r) P(|r cos θ| ≤ X) dr with ρ(r) = 2πr R(r), i.e.
// ∫_0^X ρ dr + ∫_X^∞ ρ(r) (2/π) asin(X/r) dr. `radialCdf(r)` = ∫_0^r ρ; `radialDensity(r)` = ρ(r) (1/mm).
double stripEnergy(const std::function<double(double)>& radialCdf, const std::function<double(double)>& radialDensity,
                   double halfWidthMm, double scaleMm);

} // namespace skinlab::renderer::sss
