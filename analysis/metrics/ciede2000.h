#pragma once
// CIEDE2000 colour difference (CIE 142-2001), implemented from the equations as written out in
// G. Sharma, W. Wu, E. N. Dalal, "The CIEDE2000 color-difference formula: implementation notes, supplementary
// test data, and mathematical observations", Color Research & Application 30(1):21-30, 2005 (Eqs. 1-22).
// Tested against all 34 pairs of that paper's Table 1 (tests/analysis/metrics/test_ciede2000.cpp).
namespace skinlab::metrics {

// A CIELAB colour: L* in [0, 100], a*, b* unbounded.
struct Lab {
    double lightness = 0.0; // L*
    double a = 0.0;         // a*
    double b = 0.0;         // b*
};

// ΔE00 between two CIELAB colours with the parametric factors kL = kC = kH = 1 (reference conditions).
// Symmetric in its arguments; 0 exactly for equal inputs.
double ciede2000(const Lab& first, const Lab& second);

} // namespace skinlab::metrics
