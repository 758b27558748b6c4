#pragma once
// Burley normalized diffusion (Christensen & Burley, "Approximate Reflectance Profiles for Efficient Subsurface
// Scattering", Pixar technical memo 2015), with A = 1 (unit energy per channel; albedo is applied by the renderer):
//   R(r) = (e^{−r/d} + e^{−r/(3d)}) / (8π d r)                           [1/mm²]
//   radial CDF 1 − ¼e^{−r/d} − ¾e^{−r/(3d)}
//   marginal a(x) = [K0(|x|/d) + K0(|x|/(3d))] / (4π d)                  [1/mm], K0 = modified Bessel function
// d is the per-channel shape parameter in mm (docs/methods.md: how it is derived for each material).
#include "renderer/sss/marginal.h"

#include <array>

namespace skinlab::renderer::sss {

class BurleyProfile final : public Marginal {
public:
    BurleyProfile(std::array<double, 3> shapeMm, std::string description);

    const std::array<double, 3>& shapeMm() const { return d_; }
    double radial(int channel, double rMm) const;
    double radialCumulative(int channel, double rMm) const;
    // The marginal by numerical integration of R along a line (checks the K0 closed form in tests).
    double densityNumerical(int channel, double xMm) const;
    // The marginal's CDF from the strip energy of the radial profile (numerical; checks cumulative() in tests).
    double cumulativeByStrip(int channel, double xMm) const;

    std::string description() const override { return description_; }
    double density(int channel, double xMm) const override;    // K0 closed form; +inf at x = 0
    double cumulative(int channel, double xMm) const override; // closed form in ∫K0 (tabulated once)
    double secondMoment(int channel) const override;           // 7 d² (half of the radial ∫r² = 14 d²)
    double searchRadiusMm() const override;

private:
    std::array<double, 3> d_;
    std::string description_;
};

// Slab transmittance T(t) = (A/4)(e^{−t/d} + 3 e^{−t/(3d)}) with A = 1 (d'Eon & Luebke, GPU Gems 3 ch. 14).
double burleyTransmittance(double shapeMm, double thicknessMm);

} // namespace skinlab::renderer::sss
