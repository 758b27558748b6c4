// LDR-FLIP (Andersson et al. 2020) against answers computed independently here: for two constant images the CSF
// filters (unit-sum kernels) and the feature detectors (zero-sum kernels) leave the colours unchanged and the
// feature term at 0, so FLIP is the remapped HyAB difference of the two colours, which this file computes
// with its own scalar code (docs/metrics.md, "FLIP").
#include "analysis/metrics/flip.h"

#include <gtest/gtest.h>

#include <cmath>

namespace skinlab::metrics {
namespace {

struct Colour {
    double r, g, b;
};

// Linear sRGB → XYZ (IEC 61966-2-1, D65) → CIELAB with the white (0.950428545, 1, 1.088900371) → Hunt (L, La/100,
// Lb/100), written out independently of analysis/metrics/flip.cpp.
void huntLab(Colour c, double out[3]) {
    // The sRGB matrix in exact rational form; its rows sum to the white above.
    double x = (10135552.0 * c.r + 8788810.0 * c.g + 4435075.0 * c.b) / 24577794.0;
    double y = (2613072.0 * c.r + 8788810.0 * c.g + 887015.0 * c.b) / 12288897.0;
    double z = (1425312.0 * c.r + 8788810.0 * c.g + 70074185.0 * c.b) / 73733382.0;
    auto f = [](double t) { return t > std::pow(6.0 / 29.0, 3) ? std::cbrt(t) : t * 841.0 / 108.0 + 4.0 / 29.0; };
    double fx = f(x / 0.950428545), fy = f(y), fz = f(z / 1.088900371);
    double l = 116.0 * fy - 16.0;
    out[0] = l;
    out[1] = 0.01 * l * 500.0 * (fx - fy);
    out[2] = 0.01 * l * 200.0 * (fy - fz);
}

double hyabPower(Colour first, Colour second) {
    double p[3], q[3];
    huntLab(first, p);
    huntLab(second, q);
    return std::pow(std::fabs(p[0] - q[0]) + std::hypot(p[1] - q[1], p[2] - q[2]), 0.7);
}

double expectedConstantFlip(Colour first, Colour second) {
    double cmax = hyabPower({0, 1, 0}, {0, 0, 1});
    double d = hyabPower(first, second);
    return d < 0.4 * cmax ? d * 0.95 / (0.4 * cmax) : 0.95 + (d - 0.4 * cmax) / (cmax - 0.4 * cmax) * 0.05;
}

cv::Mat constant(Colour c, int width = 48, int height = 32) {
    return cv::Mat(height, width, CV_64FC3, cv::Scalar(c.r, c.g, c.b));
}

TEST(Flip, PixelsPerDegreeOfThePaperSetUp) {
    EXPECT_NEAR(pixelsPerDegree(0.7, 3840.0, 0.7), 67.0206, 1e-4);
    EXPECT_NEAR(flipDefaultPixelsPerDegree, pixelsPerDegree(0.7, 3840.0, 0.7), 1e-12);
}

// The paper's c_max (green against blue) is 41.2761 to the digits it gives.
TEST(Flip, MaximumColourDifference) {
    EXPECT_NEAR(flipMaximumColourDifference(), 41.2761, 1e-4);
    EXPECT_NEAR(flipMaximumColourDifference(), hyabPower({0, 1, 0}, {0, 0, 1}), 1e-12);
}

TEST(Flip, IdenticalImagesScoreZero) {
    cv::Mat image(40, 56, CV_32FC3);
    cv::randu(image, 0.0f, 1.0f);
    cv::Mat map = flipErrorMap(image, image, flipDefaultPixelsPerDegree);
    double minimum = 0, maximum = 0;
    cv::minMaxLoc(map, &minimum, &maximum);
    EXPECT_EQ(minimum, 0.0);
    EXPECT_EQ(maximum, 0.0);
    EXPECT_EQ(flipMean(map), 0.0);
}

// Constant images: every pixel equals the remapped colour difference, below and above the remapping's knee
// (p_c·c_max), at the paper's PPD and at another one. Remaining tolerance: 1e-8 (measured: at most 2.9e-9). The
// filters' rounding, ~1e-16 on the zero-sum feature kernels, enters the exponent through a square root: FLIP =
// ΔE_c^(1 − ~1e-8), off by ~1e-8 · |ln ΔE_c| · ΔE_c.
TEST(Flip, ConstantImagesEqualTheRemappedColourDifference) {
    const Colour pairs[][2] = {{{0.5, 0.5, 0.5}, {0.52, 0.5, 0.48}},  // small: below the knee
                               {{0.6, 0.4, 0.3}, {0.55, 0.42, 0.33}}, // skin-like
                               {{0.1, 0.8, 0.2}, {0.9, 0.1, 0.6}},    // large: above the knee
                               {{0, 1, 0}, {0, 0, 1}}};               // c_max: FLIP 1
    for (double ppd : {flipDefaultPixelsPerDegree, 30.0}) {
        for (const auto& pair : pairs) {
            double expected = expectedConstantFlip(pair[0], pair[1]);
            cv::Mat map = flipErrorMap(constant(pair[0]), constant(pair[1]), ppd);
            double minimum = 0, maximum = 0;
            cv::minMaxLoc(map, &minimum, &maximum);
            EXPECT_NEAR(minimum, expected, 1e-8) << "ppd " << ppd;
            EXPECT_NEAR(maximum, expected, 1e-8) << "ppd " << ppd;
            EXPECT_NEAR(flipMean(map), expected, 1e-8);
        }
    }
    EXPECT_NEAR(expectedConstantFlip({0, 1, 0}, {0, 0, 1}), 1.0, 1e-12);
}

// Values outside [0, 1] are clamped after the exposure: 2.0 against 1.0 is no difference; exposure 0.5 makes them
// 1.0 against 0.5.
TEST(Flip, ClampsAfterExposure) {
    cv::Mat map = flipErrorMap(constant({2, 2, 2}), constant({1, 1, 1}), flipDefaultPixelsPerDegree);
    EXPECT_EQ(flipMean(map), 0.0);
    map = flipErrorMap(constant({2, 2, 2}), constant({1, 1, 1}), flipDefaultPixelsPerDegree, 0.5);
    EXPECT_NEAR(flipMean(map), expectedConstantFlip({1, 1, 1}, {0.5, 0.5, 0.5}), 1e-8);
}

// A thin line missing from the test image: large FLIP on the line, the map symmetric in its arguments, and zero
// beyond the filter radii.
TEST(Flip, FeaturesRaiseTheErrorAtAMissingLine) {
    cv::Mat reference = constant({0.4, 0.4, 0.4}, 96, 64);
    cv::Mat test = reference.clone();
    reference.col(48).setTo(cv::Scalar(0.8, 0.8, 0.8));
    cv::Mat map = flipErrorMap(reference, test, flipDefaultPixelsPerDegree);
    cv::Mat swapped = flipErrorMap(test, reference, flipDefaultPixelsPerDegree);
    EXPECT_EQ(cv::norm(map, swapped, cv::NORM_INF), 0.0);
    EXPECT_GT(map.at<double>(32, 48), 0.3);
    EXPECT_EQ(map.at<double>(32, 2), 0.0); // farther than the CSF and feature radii (10 and 9 pixels)
    double mask = flipMean(map, cv::Mat::zeros(64, 96, CV_8UC1));
    EXPECT_TRUE(std::isnan(mask));
}

TEST(Flip, RejectsANonPositivePixelsPerDegree) {
    EXPECT_THROW(flipErrorMap(constant({0, 0, 0}), constant({1, 1, 1}), 0.0), std::invalid_argument);
}

} // namespace
} // namespace skinlab::metrics
