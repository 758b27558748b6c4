#pragma once
// Colour conversions used by the metrics: linear Rec.709 RGB -> CIE XYZ (D65) -> CIELAB, and the display
// encoding the metrics apply to a linear render before computing ΔE00, PSNR and SSIM.
#include "analysis/metrics/ciede2000.h"

namespace skinlab::metrics {

struct Xyz {
    double x = 0.0;
    double y = 0.0;
    double z = 0.0;
};

// Linear Rec.709 / sRGB primaries, D65 white -> CIE 1931 XYZ (IEC 61966-2-1 matrix). RGB (1, 1, 1) maps to the
// D65 white with Y = 1.
Xyz linearRec709ToXyz(double red, double green, double blue);

// Relative luminance Y of linear Rec.709 RGB (the middle row of the matrix above).
double luminanceRec709(double red, double green, double blue);

// CIE XYZ -> CIELAB relative to the D65 white of the matrix above (Y_white = 1), CIE 15:2004 with the exact
// constants ε = 216/24389 and κ = 24389/27.
Lab xyzToLab(const Xyz& xyz);

// The display encoding for ΔE00 (docs/metrics.md): linear RGB × exposure, each channel clipped to [0, 1], taken
// as XYZ with Y_white = 1, then CIELAB. Non-finite values count as 0 (black).
Lab displayLab(double red, double green, double blue, double exposure);

// The sRGB transfer function (IEC 61966-2-1) of a value clipped to [0, 1]; used for PSNR and SSIM inputs.
double encodeSrgb(double linear);

} // namespace skinlab::metrics
