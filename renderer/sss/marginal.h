#pragma once
// A 1-D kernel density per colour channel: the marginal (pre-integrated kernel) a(x) of a radial diffusion profile,
// a(x) = ∫ R(√(x²+y²)) dy (d'Eon & Luebke, GPU Gems 3 ch. 14), or a tabulated kernel. Distances in millimetres on the surface;
// each channel integrates to 1 over the real line. This is what the discretisation turns into taps.
#include <string>

namespace skinlab::renderer::sss {

constexpr int kChannels = 3; // R, G, B (linear Rec.709)

class Marginal {
public:
    virtual ~Marginal() = default;

    // Human-readable source, e.g. "d'Eon six-Gaussian skin profile".
    virtual std::string description() const = 0;
    // a_c(x) in 1/mm; symmetric in x; may be +inf at x = 0 (Burley's marginal has a logarithmic singularity).
    virtual double density(int channel, double xMm) const = 0;
    // ∫_{-∞}^{x} a_c, in [0, 1], non-decreasing, cumulative(c, 0) = 0.5.
    virtual double cumulative(int channel, double xMm) const = 0;
    // ∫ x² a_c(x) dx in mm² (the squared RMS width of the marginal).
    virtual double secondMoment(int channel) const = 0;
    // A length (mm) beyond which every channel's tails are negligible (< 1e-9 of the energy); bounds searches.
    virtual double searchRadiusMm() const = 0;

    // Energy of channel c outside [−x, x] (x ≥ 0): 2 (1 − cumulative(c, x)).
    double tailEnergy(int channel, double xMm) const;
    // Smallest x ≥ 0 with tailEnergy(c, x) ≤ tail for every channel (bisection).
    double truncationRadiusMm(double tail) const;
    // Inverse of cumulative(c, ·) by bisection on [−searchRadius, searchRadius].
    double quantile(int channel, double probability) const;
    // Channel with the largest second moment (the "widest" channel).
    int widestChannel() const;
};

} // namespace skinlab::renderer::sss
