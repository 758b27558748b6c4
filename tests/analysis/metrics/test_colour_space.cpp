// Linear Rec.709 -> XYZ (D65) -> CIELAB and the display encoding of the metrics, against tabulated values.
#include "analysis/metrics/colour_space.h"

#include <gtest/gtest.h>

#include <cmath>

namespace skinlab::metrics {
namespace {

TEST(ColourSpace, WhiteAndBlackMapToTheEndsOfTheLightnessAxis) {
    Lab white = displayLab(1.0, 1.0, 1.0, 1.0);
    EXPECT_NEAR(white.lightness, 100.0, 1e-9);
    EXPECT_NEAR(white.a, 0.0, 1e-9);
    EXPECT_NEAR(white.b, 0.0, 1e-9);
    Lab black = displayLab(0.0, 0.0, 0.0, 1.0);
    EXPECT_EQ(black.lightness, 0.0);
    // Linear 0.18 grey: Y = 0.18 -> L* = 116·0.18^(1/3) − 16 = 49.4961 (CIE 15:2004).
    EXPECT_NEAR(displayLab(0.18, 0.18, 0.18, 1.0).lightness, 116.0 * std::cbrt(0.18) - 16.0, 1e-9);
    // Exposure multiplies before the clip: 0.09 × 2 is the same grey; 10 × 0.5 clips to white.
    EXPECT_NEAR(displayLab(0.09, 0.09, 0.09, 2.0).lightness, displayLab(0.18, 0.18, 0.18, 1.0).lightness, 1e-9);
    EXPECT_NEAR(displayLab(0.5, 0.5, 0.5, 10.0).lightness, 100.0, 1e-9);
}

// sRGB primaries in CIELAB (D65), standard values to 3 decimals (e.g. Lindbloom's calculator).
TEST(ColourSpace, PrimariesMatchTheirTabulatedLab) {
    Lab red = displayLab(1.0, 0.0, 0.0, 1.0);
    EXPECT_NEAR(red.lightness, 53.241, 2e-3);
    EXPECT_NEAR(red.a, 80.092, 2e-3);
    EXPECT_NEAR(red.b, 67.203, 2e-3);
    Lab blue = displayLab(0.0, 0.0, 1.0, 1.0);
    EXPECT_NEAR(blue.lightness, 32.297, 2e-3);
    EXPECT_NEAR(blue.a, 79.188, 2e-3);
    EXPECT_NEAR(blue.b, -107.860, 2e-3);
}

TEST(ColourSpace, SrgbEncodingFollowsIec61966) {
    EXPECT_EQ(encodeSrgb(0.0), 0.0);
    EXPECT_NEAR(encodeSrgb(1.0), 1.0, 1e-12);
    EXPECT_NEAR(encodeSrgb(0.002), 12.92 * 0.002, 1e-12);
    EXPECT_NEAR(encodeSrgb(0.18), 1.055 * std::pow(0.18, 1 / 2.4) - 0.055, 1e-12);
    EXPECT_EQ(encodeSrgb(2.0), encodeSrgb(1.0)); // clipped
}

} // namespace
} // namespace skinlab::metrics
