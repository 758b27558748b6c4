#pragma once
// The artistic method's own [sss] keys as its typed parameters (declared in artistic.cpp).
#include "renderer/sss/sss_params.h"

#include <array>

namespace skinlab::renderer::sss {

// The kernel of Jimenez's demo (its baseline values): per-channel strength and falloff, each in [0, 1]
// (sss.artistic_strength, sss.artistic_falloff; artistic_kernel.h).
struct ArtisticParams {
    std::array<double, 3> strength{0.48, 0.41, 0.28};
    std::array<double, 3> falloff{1.0, 0.37, 0.3};
};

// The artistic keys of `params` (the defaults above for a parameter set of another method).
ArtisticParams artisticParams(const SssParams& params);

} // namespace skinlab::renderer::sss
