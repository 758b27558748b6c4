#pragma once
// The "artistic" separable kernel of Jimenez's Separable SSS demo (2012/2015), as described in the thesis §3.1.3
// (method M3 of docs/methods.md): RANGE = 3 if N > 20 else 2; offsets o_i = RANGE·sign(t)·t²/RANGE² for t evenly
// spaced in [−RANGE, RANGE]; weight_i = trapezoid area × profile(o_i) with profile(r) = Σ_{i≥2} w_i^red G(v_i,
// r/(0.001 + falloff_c)) (d'Eon's red weights without the narrowest lobe, evaluated along a line, i.e. a slice of
// the radial profile, not its marginal); each channel normalised; then the centre weight becomes
// lerp(1, w_centre, strength_c) and every other weight w · strength_c. Offsets are in the demo's kernel units,
// which are profile millimetres (the demo scales them by sssWidth / 3; here by width_mm / 3).
// Fixed here: the thesis code wrote the centre weight from the wrong array slots (a channel mix-up); this
// implementation treats every channel independently.
#include "renderer/sss/kernel.h"

#include <array>
#include <vector>

namespace skinlab::renderer::sss {

// Taps in profile millimetres (before the width_mm / 3 scale), ascending offsets.
std::vector<KernelTap> artisticTaps(int samples, const std::array<double, 3>& strength,
                                    const std::array<double, 3>& falloff);

} // namespace skinlab::renderer::sss
