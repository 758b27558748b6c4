#include "analysis/metrics/ciede2000.h"

#include <cmath>
#include <numbers>

namespace skinlab::metrics {
namespace {

constexpr double degreesPerRadian = 180.0 / std::numbers::pi;
constexpr double radiansPerDegree = std::numbers::pi / 180.0;
// 25^7, the constant of the chroma compensation G (Eq. 3) and the rotation term R_C (Eq. 21).
constexpr double twentyFiveToTheSeventh = 6103515625.0;

// Hue angle in degrees within [0, 360); 0 for a neutral colour (Eq. 7: h' = 0 when a' = b' = 0).
double hueDegrees(double b, double aPrime) {
    if (b == 0.0 && aPrime == 0.0) return 0.0;
    double hue = std::atan2(b, aPrime) * degreesPerRadian;
    return hue < 0.0 ? hue + 360.0 : hue;
}

double seventhPower(double x) {
    double squared = x * x;
    return squared * squared * squared * x;
}

} // namespace

double ciede2000(const Lab& first, const Lab& second) {
    // Step 1 (Eqs. 2-7): a' stretched by G to correct the a* axis for near-neutral colours, then C' and h'.
    double chroma1 = std::hypot(first.a, first.b);
    double chroma2 = std::hypot(second.a, second.b);
    double meanChroma7 = seventhPower(0.5 * (chroma1 + chroma2));
    double g = 0.5 * (1.0 - std::sqrt(meanChroma7 / (meanChroma7 + twentyFiveToTheSeventh)));
    double aPrime1 = (1.0 + g) * first.a;
    double aPrime2 = (1.0 + g) * second.a;
    double chromaPrime1 = std::hypot(aPrime1, first.b);
    double chromaPrime2 = std::hypot(aPrime2, second.b);
    double hue1 = hueDegrees(first.b, aPrime1);
    double hue2 = hueDegrees(second.b, aPrime2);

    // Step 2 (Eqs. 8-11): differences ΔL', ΔC', Δh' (shortest way round the hue circle), ΔH'.
    double deltaLightness = second.lightness - first.lightness;
    double deltaChroma = chromaPrime2 - chromaPrime1;
    bool eitherNeutral = chromaPrime1 * chromaPrime2 == 0.0;
    double deltaHueAngle = 0.0;
    if (!eitherNeutral) {
        deltaHueAngle = hue2 - hue1;
        if (deltaHueAngle > 180.0) deltaHueAngle -= 360.0;
        else if (deltaHueAngle < -180.0) deltaHueAngle += 360.0;
    }
    double deltaHue = 2.0 * std::sqrt(chromaPrime1 * chromaPrime2) * std::sin(0.5 * deltaHueAngle * radiansPerDegree);

    // Step 3 (Eqs. 12-22): means, weighting functions and the blue-region rotation term.
    double meanLightness = 0.5 * (first.lightness + second.lightness);
    double meanChromaPrime = 0.5 * (chromaPrime1 + chromaPrime2);
    double meanHue = hue1 + hue2; // Eq. 14: the sum when either colour is neutral
    if (!eitherNeutral) {
        if (std::fabs(hue1 - hue2) <= 180.0) meanHue = 0.5 * (hue1 + hue2);
        else if (hue1 + hue2 < 360.0) meanHue = 0.5 * (hue1 + hue2 + 360.0);
        else meanHue = 0.5 * (hue1 + hue2 - 360.0);
    }
    double t = 1.0 - 0.17 * std::cos((meanHue - 30.0) * radiansPerDegree) +
               0.24 * std::cos((2.0 * meanHue) * radiansPerDegree) +
               0.32 * std::cos((3.0 * meanHue + 6.0) * radiansPerDegree) -
               0.20 * std::cos((4.0 * meanHue - 63.0) * radiansPerDegree);
    double hueOffset = (meanHue - 275.0) / 25.0;
    double deltaTheta = 30.0 * std::exp(-hueOffset * hueOffset); // degrees
    double meanChromaPrime7 = seventhPower(meanChromaPrime);
    double rotationChroma = 2.0 * std::sqrt(meanChromaPrime7 / (meanChromaPrime7 + twentyFiveToTheSeventh));
    double lightnessOffset2 = (meanLightness - 50.0) * (meanLightness - 50.0);
    double weightLightness = 1.0 + 0.015 * lightnessOffset2 / std::sqrt(20.0 + lightnessOffset2);
    double weightChroma = 1.0 + 0.045 * meanChromaPrime;
    double weightHue = 1.0 + 0.015 * meanChromaPrime * t;
    double rotation = -std::sin(2.0 * deltaTheta * radiansPerDegree) * rotationChroma;

    double lightnessTerm = deltaLightness / weightLightness;
    double chromaTerm = deltaChroma / weightChroma;
    double hueTerm = deltaHue / weightHue;
    double squared =
        lightnessTerm * lightnessTerm + chromaTerm * chromaTerm + hueTerm * hueTerm + rotation * chromaTerm * hueTerm;
    // The rotation term can make the sum a rounding error below zero for identical colours.
    return std::sqrt(squared > 0.0 ? squared : 0.0);
}

} // namespace skinlab::metrics
