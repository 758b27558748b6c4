#pragma once
// Discretisation of a 1-D marginal into N taps (N odd, 3…101), every channel normalised to sum 1
// (docs/methods.md, "Discretisation").
#include "renderer/sss/kernel.h"
#include "renderer/sss/marginal.h"

#include <vector>

namespace skinlab::renderer::sss {

// Quadratic spacing with trapezoid weights (Jimenez's demo): t_i evenly spaced in [−1, 1], offsets R·sign(t)·t²,
// weight = a(o_i) · (|o_i − o_{i−1}| + |o_i − o_{i+1}|)/2, R = the radius leaving kTruncatedTail of the widest
// channel outside. Where a is singular (Burley's centre), the tap's cell integral replaces a · area.
std::vector<KernelTap> quadraticTaps(const Marginal& marginal, int samples);

// Equal-probability importance sampling (Mikkelsen 2010): cells [Q(k/N), Q((k+1)/N)] of the widest channel's
// cumulative Q; tap k at the cell's median Q((k+½)/N); every channel's weight is its exact energy in the cell, so
// the widest channel gets 1/N per tap and nothing is truncated.
std::vector<KernelTap> importanceTaps(const Marginal& marginal, int samples);

std::vector<KernelTap> discretise(const Marginal& marginal, int samples, TapPlacement placement);

// Divides each channel by its sum (asserts a positive sum).
void normaliseChannels(std::vector<KernelTap>& taps);

} // namespace skinlab::renderer::sss
