#include "analysis/metrics/colour_space.h"

#include <algorithm>
#include <cmath>

namespace skinlab::metrics {
namespace {

// IEC 61966-2-1 (sRGB) RGB -> XYZ matrix for D65, to 7 decimals as in Lindbloom's tabulation.
constexpr double matrix[3][3] = {
    {0.4124564, 0.3575761, 0.1804375}, {0.2126729, 0.7151522, 0.0721750}, {0.0193339, 0.1191920, 0.9503041}};
// The white is the image of RGB (1, 1, 1) through the same matrix, so a neutral grey has a* = b* = 0 to rounding.
constexpr double whiteX = matrix[0][0] + matrix[0][1] + matrix[0][2];
constexpr double whiteY = matrix[1][0] + matrix[1][1] + matrix[1][2];
constexpr double whiteZ = matrix[2][0] + matrix[2][1] + matrix[2][2];

constexpr double epsilon = 216.0 / 24389.0; // (6/29)^3
constexpr double kappa = 24389.0 / 27.0;    // (29/3)^3

double labCompand(double ratio) { return ratio > epsilon ? std::cbrt(ratio) : (kappa * ratio + 16.0) / 116.0; }

double clipUnit(double value) {
    if (!std::isfinite(value)) return value > 0.0 ? 1.0 : 0.0; // +inf is over-exposed white; NaN and -inf black
    return std::clamp(value, 0.0, 1.0);
}

} // namespace

Xyz linearRec709ToXyz(double red, double green, double blue) {
    return {matrix[0][0] * red + matrix[0][1] * green + matrix[0][2] * blue,
            matrix[1][0] * red + matrix[1][1] * green + matrix[1][2] * blue,
            matrix[2][0] * red + matrix[2][1] * green + matrix[2][2] * blue};
}

double luminanceRec709(double red, double green, double blue) {
    return matrix[1][0] * red + matrix[1][1] * green + matrix[1][2] * blue;
}

Lab xyzToLab(const Xyz& xyz) {
    double fx = labCompand(xyz.x / whiteX);
    double fy = labCompand(xyz.y / whiteY);
    double fz = labCompand(xyz.z / whiteZ);
    return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

Lab displayLab(double red, double green, double blue, double exposure) {
    return xyzToLab(linearRec709ToXyz(clipUnit(red * exposure), clipUnit(green * exposure), clipUnit(blue * exposure)));
}

double encodeSrgb(double linear) {
    double v = clipUnit(linear);
    return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

} // namespace skinlab::metrics
