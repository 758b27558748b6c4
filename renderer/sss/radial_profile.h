#pragma once
// The radial diffusion profile the object-space reference convolves with: the same profile as the screen-space
// methods (sss.profile: "deon" by default, or "burley" with sss.material), at the same physical width
// (sss.width_mm: a profile distance of o mm lies at o · width_mm / 3 mm on the surface, as in renderer/sss/kernel.h),
// evaluated at true 3-D distances. Tabulated kernels (sss.profile = "file:...") are 1-D marginals without a radial
// form and are rejected.
#include "renderer/sss/sss_params.h"

#include <memory>
#include <string>

namespace skinlab::renderer::sss {

class RadialProfile {
public:
    virtual ~RadialProfile() = default;
    virtual std::string description() const = 0;
    // R_c(r) on the surface, 1/mm² (unit integral over the plane); may be +inf at r = 0 (Burley).
    virtual double radial(int channel, double rMm) const = 0;
    // Energy of channel c inside the disc of radius r: ∫_0^r 2πs R_c(s) ds, in [0, 1].
    virtual double cumulative(int channel, double rMm) const = 0;

    // Smallest radius (mm) outside which every channel has at most `tail` of its energy (bisection).
    double cutoffRadiusMm(double tail) const;
};

// The profile of `params` (method-independent: only profile, material and width_mm are read). Throws InputError
// ("sss.profile: ...") for a tabulated profile.
std::unique_ptr<RadialProfile> makeRadialProfile(const SssParams& params);

} // namespace skinlab::renderer::sss
