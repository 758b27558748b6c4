// ColorVideoVDP (analysis/metrics/cvvdp.h): agreement with the reference implementation on published vectors
// ($SKINLAB_REFERENCE/cvvdp, skipped when absent) and properties that need no external data.
#include "analysis/metrics/cvvdp.h"
#include "analysis/metrics/metric_render.h"
#include "common/error.h"
#include "tests/common/temp_folder.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

#include <OpenImageIO/imageio.h>

#include <opencv2/imgproc.hpp>

namespace {
namespace fs = std::filesystem;
using namespace skinlab::metrics;

// $SKINLAB_REFERENCE or the default next to the source tree (as the separable-kernel tests do).
fs::path cvvdpReferenceDir() {
    const char* env = std::getenv("SKINLAB_REFERENCE");
    const fs::path root = env && *env ? fs::path(env) : fs::path(SKINLAB_SOURCE_DIR) / ".." / "shared" / "reference";
    return root / "cvvdp";
}

cv::Mat loadLinear(const fs::path& path) { return loadMetricRender(path, RenderRole::test).beauty; }

// A smooth, textured linear image (values in (0, 1)).
cv::Mat texturedImage(int width, int height, unsigned seed = 7) {
    cv::Mat image(height, width, CV_32FC3);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> noise(-0.05f, 0.05f);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const float u = float(x) / float(width), v = float(y) / float(height);
            const float base = 0.25f + 0.2f * std::sin(40.0f * u) * std::cos(25.0f * v);
            image.at<cv::Vec3f>(y, x) = {std::clamp(base + 0.1f * u + noise(rng), 0.0f, 1.0f),
                                         std::clamp(base + noise(rng), 0.0f, 1.0f),
                                         std::clamp(base - 0.1f * v + noise(rng), 0.0f, 1.0f)};
        }
    return image;
}

// The sRGB EOTF in single precision, as the reference applies it to display-encoded input.
float decodeSrgb(float v) { return v > 0.04045f ? std::pow((v + 0.055f) / 1.055f, 2.4f) : v / 12.92f; }

// A horizontal sine grating of `period` pixels under a Gaussian window (σ = width/4) on the sRGB-encoded base
// (0.5, 0.45, 0.4), amplitude `amplitude` times `chroma` per channel; computed in double, stored as float like
// the Python script that produced the reference values below, then decoded to linear.
cv::Mat grating(int width, int height, double period, double amplitude, const cv::Vec3d& chroma) {
    cv::Mat image(height, width, CV_32FC3);
    const double base[3] = {0.5, 0.45, 0.4};
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const double dx = x - width / 2.0, dy = y - height / 2.0, sigma = width / 4.0;
            const double s = std::sin(2.0 * M_PI * x / period) * std::exp(-(dx * dx + dy * dy) / (2.0 * sigma * sigma));
            for (int c = 0; c < 3; ++c)
                image.at<cv::Vec3f>(y, x)[c] = decodeSrgb(static_cast<float>(base[c] + amplitude * chroma[c] * s));
        }
    return image;
}

cv::Mat blurred(const cv::Mat& image, double sigma) {
    cv::Mat out;
    cv::GaussianBlur(image, out, {0, 0}, sigma, sigma, cv::BORDER_REFLECT);
    return out;
}

TEST(Cvvdp, ReferenceVectorsAgreeWithinAThousandthOfAJod) {
    const fs::path dir = cvvdpReferenceDir();
    const fs::path expectedPath = dir / "vectors" / "expected.json";
    if (!fs::exists(expectedPath))
        GTEST_SKIP() << "ColorVideoVDP vectors " << expectedPath << " absent (set SKINLAB_REFERENCE to the folder "
                     << "holding cvvdp/)";
    std::ifstream in(expectedPath);
    const nlohmann::json cases = nlohmann::json::parse(in);
    ASSERT_FALSE(cases.empty());
    for (const auto& entry : cases) {
        const std::string test = entry.at("test"), reference = entry.at("reference"), display = entry.at("display");
        const double expected = entry.at("jod");
        const CvvdpResult result = cvvdp(loadLinear(dir / "vectors" / reference), loadLinear(dir / "vectors" / test),
                                         cvvdpDisplay(display), false);
        std::printf("%s vs %s on %s: expected %.4f, got %.5f (difference %+.5f)\n", test.c_str(), reference.c_str(),
                    display.c_str(), expected, result.jod, result.jod - expected);
        // The vectors are rounded to 4 decimals: 0.001 JOD is the aim, 0.01 the acceptance.
        EXPECT_NEAR(result.jod, expected, 0.001) << test << " vs " << reference << " on " << display;
    }
}

TEST(Cvvdp, IdenticalImagesScoreTenExactly) {
    const cv::Mat image = texturedImage(320, 200);
    const CvvdpResult result = cvvdp(image, image.clone(), cvvdpDisplay("standard_fhd"));
    EXPECT_EQ(result.jod, 10.0);
    EXPECT_EQ(result.quality, 0.0);
    double minimum = 0.0, maximum = 0.0;
    cv::minMaxLoc(result.map, &minimum, &maximum);
    EXPECT_EQ(minimum, 0.0);
    EXPECT_EQ(maximum, 0.0);
}

// Values from the reference implementation (gfxdisp/ColorVideoVDP at its v0.5.6 parameters, PyTorch on a CPU):
// the same gratings as float32 sRGB-encoded arrays, `cvvdp(display_name=..., display_geometry=...).predict(test,
// reference, dim_order="HWC")`, 256×192 pixels; recorded to 5 decimals, all reproduced to 5 decimals.
TEST(Cvvdp, GratingsMatchTheReferenceImplementation) {
    struct Case {
        const char* name;
        double period;
        cv::Vec3d chroma;
        double referenceAmplitude, testAmplitude;
        const char* display;
        double ppd; // > 0: a custom geometry with this ppd
        double expected;
    };
    const Case cases[] = {
        {"achromatic", 8.0, {1, 1, 1}, 0.10, 0.14, "standard_fhd", 0.0, 8.55060},
        {"red-green", 16.0, {1, -1, 0}, 0.05, 0.08, "standard_fhd", 0.0, 9.46936},
        {"achromatic, 4K", 8.0, {1, 1, 1}, 0.10, 0.14, "standard_4k", 0.0, 9.34967},
        {"achromatic, 20 ppd", 8.0, {1, 1, 1}, 0.10, 0.14, "standard_fhd", 20.0, 8.19198},
        // Contrast from min_luminance, a phone's ppd (120.6).
        {"achromatic, phone", 8.0, {1, 1, 1}, 0.10, 0.14, "standard_phone", 0.0, 9.69909},
        // Geometry from the diagonal field of view (13.15 ppd).
        {"achromatic, head-mounted", 8.0, {1, 1, 1}, 0.10, 0.14, "standard_hmd", 0.0, 8.37041},
        // Absolute-linear HDR display: the reference was given the linear values × 1500 cd/m² (its peak).
        {"achromatic, linear HDR", 8.0, {1, 1, 1}, 0.10, 0.14, "standard_hdr_linear", 0.0, 9.06131},
    };
    for (const Case& c : cases) {
        CvvdpDisplay display = cvvdpDisplay(c.display);
        if (c.ppd > 0.0) {
            CvvdpDisplayOverrides overrides;
            overrides.pixelsPerDegree = c.ppd;
            display = applyCvvdpOverrides(display, overrides);
        }
        const CvvdpResult result = cvvdp(grating(256, 192, c.period, c.referenceAmplitude, c.chroma),
                                         grating(256, 192, c.period, c.testAmplitude, c.chroma), display, false);
        std::printf("grating %s: expected %.5f, got %.5f\n", c.name, c.expected, result.jod);
        EXPECT_NEAR(result.jod, c.expected, 1e-4) << c.name;
    }
}

// The published geometry: ppd of the standard displays as the reference implementation reports them.
TEST(Cvvdp, DisplayModelsLoadWithTheReferenceGeometry) {
    const auto names = cvvdpDisplayNames();
    EXPECT_EQ(names.size(), 22u);
    EXPECT_EQ(names.front(), "standard_4k");
    for (const std::string& name : names) {
        const CvvdpDisplay display = cvvdpDisplay(name);
        EXPECT_GT(display.pixelsPerDegree, 5.0) << name;
        EXPECT_GT(display.peakLuminance, 0.0) << name;
        EXPECT_GT(display.contrast, 1.0) << name;
    }
    // vvdp_display_geometry.load(name).get_ppd() of the reference implementation, in file order.
    const double referencePpd[] = {75.40244934516305,  75.40244934516305,  75.40244934516305,  75.40244934516305,
                                   75.40244934516305,  25.228336461402645, 37.842503853602885, 13.153262507309297,
                                   120.56081547997547, 60.54800551173376,  37.842503853602885, 13.153262507309297,
                                   159.61187740300227, 159.61187740300227, 159.61187740300227, 159.61187740300227,
                                   159.61187740300227, 92.39150975665837,  98.79241965219656,  120.41073840016432,
                                   120.41073840016432, 75.19218845811538};
    ASSERT_EQ(std::size(referencePpd), names.size());
    for (std::size_t i = 0; i < names.size(); ++i)
        EXPECT_NEAR(cvvdpDisplay(names[i]).pixelsPerDegree, referencePpd[i], 1e-9) << names[i];
    const CvvdpDisplay fhd = cvvdpDisplay("standard_fhd");
    EXPECT_DOUBLE_EQ(fhd.blackLevel(), 0.2);                        // 200 cd/m² / 1000
    EXPECT_NEAR(fhd.reflectedLevel(), 250.0 / M_PI * 0.005, 1e-12); // 250 lux, k_refl 0.005
    EXPECT_EQ(cvvdpDisplay("standard_hdr_linear").eotf, "linear");
    EXPECT_THROW(cvvdpDisplay("no_such_display"), skinlab::InputError);
}

TEST(Cvvdp, DisplayOverridesAreCheckedAndRecomputeTheGeometry) {
    const CvvdpDisplay fhd = cvvdpDisplay("standard_fhd");
    CvvdpDisplayOverrides same;
    same.resolution = std::array<int, 2>{1920, 1080};
    same.diagonalInches = 24.0;
    same.viewingDistanceMetres = 0.6;
    EXPECT_NEAR(applyCvvdpOverrides(fhd, same).pixelsPerDegree, fhd.pixelsPerDegree, 1e-9);
    CvvdpDisplayOverrides farther;
    farther.viewingDistanceMetres = 1.2;
    EXPECT_GT(applyCvvdpOverrides(fhd, farther).pixelsPerDegree, 1.9 * fhd.pixelsPerDegree);
    auto rejects = [&](auto set) {
        CvvdpDisplayOverrides o;
        set(o);
        EXPECT_THROW(applyCvvdpOverrides(fhd, o), skinlab::InputError);
    };
    rejects([](CvvdpDisplayOverrides& o) { o.pixelsPerDegree = 0.0; });
    rejects([](CvvdpDisplayOverrides& o) { o.pixelsPerDegree = -3.0; });
    rejects([](CvvdpDisplayOverrides& o) { o.peakLuminance = std::nan(""); });
    rejects([](CvvdpDisplayOverrides& o) { o.contrast = 0.5; });
    rejects([](CvvdpDisplayOverrides& o) { o.ambientIlluminance = -1.0; });
    rejects([](CvvdpDisplayOverrides& o) { o.reflectivity = 1.5; });
    rejects([](CvvdpDisplayOverrides& o) { o.resolution = std::array<int, 2>{0, 1080}; });
    // A model given by its field of view has no diagonal: a distance alone cannot recompute its geometry.
    CvvdpDisplayOverrides distanceOnly;
    distanceOnly.viewingDistanceMetres = 1.0;
    EXPECT_THROW(applyCvvdpOverrides(cvvdpDisplay("standard_hmd"), distanceOnly), skinlab::InputError);
}

// A change along a direction of linear RGB that keeps L + M (DKL's achromatic axis) leaves the achromatic
// channel's band differences at zero (to rounding) while the chromatic channels see it.
TEST(Cvvdp, IsoluminantChangeIsSeenOnlyByTheChromaticChannels) {
    // L + M per unit of linear R, G, B: rows 1 + 2 of the CIE 2006 LMS matrix times sRGB's RGB→XYZ (the
    // reference's matrices); a change orthogonal to it keeps the achromatic channel.
    const double xyzToLm[3] = {0.187596268556126 - 0.133397430663221, 0.585168649077728 + 0.405505777260049,
                               -0.026384263306304 + 0.034502127690364};
    const double rgbToXyz[3][3] = {
        {0.4124564, 0.3575761, 0.1804375}, {0.2126729, 0.7151522, 0.0721750}, {0.0193339, 0.1191920, 0.9503041}};
    double achromatic[3];
    for (int c = 0; c < 3; ++c)
        achromatic[c] = xyzToLm[0] * rgbToXyz[0][c] + xyzToLm[1] * rgbToXyz[1][c] + xyzToLm[2] * rgbToXyz[2][c];
    // Direction in the R-G plane with zero achromatic change.
    const cv::Vec3f direction(static_cast<float>(achromatic[1]), static_cast<float>(-achromatic[0]), 0.0f);
    cv::Mat reference(128, 160, CV_32FC3, cv::Scalar(0.3, 0.3, 0.3));
    cv::Mat test = reference.clone();
    for (int y = 40; y < 88; ++y)
        for (int x = 50; x < 110; ++x) test.at<cv::Vec3f>(y, x) += 0.2f * direction;
    const CvvdpResult result = cvvdp(reference, test, cvvdpDisplay("standard_fhd"), false);
    EXPECT_LT(result.jod, 10.0);
    double achromaticMax = 0.0, chromaticMax = 0.0;
    for (std::size_t band = 0; band < result.bandFrequencies.size(); ++band) {
        achromaticMax = std::max(achromaticMax, result.bandQuality[0][band]);
        chromaticMax = std::max({chromaticMax, result.bandQuality[1][band], result.bandQuality[2][band]});
    }
    EXPECT_LT(achromaticMax, 1e-4);
    EXPECT_GT(chromaticMax, 1000.0 * achromaticMax);
}

TEST(Cvvdp, SmallAndLargeImages) {
    for (int size : {16, 9}) {
        const cv::Mat image = texturedImage(size, size);
        const CvvdpResult same = cvvdp(image, image, cvvdpDisplay("standard_fhd"));
        EXPECT_EQ(same.jod, 10.0) << size;
        const CvvdpResult changed = cvvdp(image, cv::Mat(image * 0.8f), cvvdpDisplay("standard_fhd"));
        EXPECT_TRUE(std::isfinite(changed.jod)) << size;
        EXPECT_LT(changed.jod, 10.0) << size;
        EXPECT_EQ(changed.map.size(), image.size());
    }
    const cv::Mat large = texturedImage(1920, 1080);
    const CvvdpResult result = cvvdp(large, blurred(large, 1.5), cvvdpDisplay("standard_4k"));
    EXPECT_TRUE(std::isfinite(result.jod));
    EXPECT_LT(result.jod, 10.0);
    EXPECT_EQ(result.map.size(), large.size());
    EXPECT_EQ(result.bandFrequencies.size(), 9u); // 75.4 ppd: 8 Laplacian bands (to 0.19 cpd) and the baseband
}

// More pixels per degree (a farther or denser display) makes the same blur harder to see.
TEST(Cvvdp, MorePixelsPerDegreeMakesABlurLessVisible) {
    const cv::Mat image = texturedImage(320, 240);
    const cv::Mat test = blurred(image, 2.0);
    double previous = -1.0;
    for (double ppd : {15.0, 30.0, 60.0, 120.0}) {
        CvvdpDisplayOverrides overrides;
        overrides.pixelsPerDegree = ppd;
        const double jod = cvvdp(image, test, applyCvvdpOverrides(cvvdpDisplay("standard_fhd"), overrides), false).jod;
        EXPECT_GT(jod, previous) << ppd;
        previous = jod;
    }
}

// Linear EXR input: read through the metrics loader (float → linear), the same JOD as the in-memory images;
// values above 1 clip at the display's peak, and a brighter display makes the same relative change more visible.
TEST(Cvvdp, LinearExrInputAndDisplayPeak) {
    const skinlab::test_support::TempFolder temp;
    const fs::path& folder = temp.path();
    cv::Mat reference = texturedImage(200, 150) * 1.5f; // HDR: some values above 1
    cv::Mat test = blurred(reference, 1.5);
    auto writeExr = [&](const fs::path& path, const cv::Mat& image) {
        auto out = OIIO::ImageOutput::create(path.string());
        ASSERT_TRUE(out);
        OIIO::ImageSpec spec(image.cols, image.rows, 3, OIIO::TypeDesc::FLOAT);
        ASSERT_TRUE(out->open(path.string(), spec));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, image.ptr<float>()));
        out->close();
    };
    writeExr(folder / "reference.exr", reference);
    writeExr(folder / "test.exr", test);
    const CvvdpDisplay fhd = cvvdpDisplay("standard_fhd");
    const double fromFiles = cvvdp(loadLinear(folder / "reference.exr"), loadLinear(folder / "test.exr"), fhd).jod;
    EXPECT_DOUBLE_EQ(fromFiles, cvvdp(reference, test, fhd).jod);

    // Clipping: differences only above 1 are invisible.
    cv::Mat brighter = reference.clone();
    for (auto it = brighter.begin<cv::Vec3f>(); it != brighter.end<cv::Vec3f>(); ++it)
        for (int c = 0; c < 3; ++c)
            if ((*it)[c] > 1.0f) (*it)[c] *= 2.0f;
    EXPECT_EQ(cvvdp(reference, brighter, fhd, false).jod, 10.0);
    EXPECT_EQ(cvvdp(reference, brighter, cvvdpDisplay("standard_hdr_linear"), false).jod, 10.0);

    // The same relative blur on a 1000 cd/m² display is more visible than on a 50 cd/m² one.
    CvvdpDisplayOverrides dim, bright;
    dim.peakLuminance = 50.0;
    bright.peakLuminance = 1000.0;
    const cv::Mat ldr = texturedImage(200, 150);
    EXPECT_LT(cvvdp(ldr, blurred(ldr, 1.5), applyCvvdpOverrides(fhd, bright), false).jod,
              cvvdp(ldr, blurred(ldr, 1.5), applyCvvdpOverrides(fhd, dim), false).jod);
}

// The visibility map is zero where the images agree and concentrates where they differ.
TEST(Cvvdp, MapLocalisesTheDifference) {
    const cv::Mat image = texturedImage(256, 256);
    cv::Mat test = image.clone();
    blurred(image, 3.0)(cv::Rect(160, 160, 64, 64)).copyTo(test(cv::Rect(160, 160, 64, 64)));
    const CvvdpResult result = cvvdp(image, test, cvvdpDisplay("standard_fhd"));
    cv::Mat inside = cv::Mat::zeros(256, 256, CV_8UC1), outside = cv::Mat::zeros(256, 256, CV_8UC1);
    inside(cv::Rect(160, 160, 64, 64)).setTo(255);
    outside(cv::Rect(0, 0, 96, 96)).setTo(255);
    EXPECT_GT(cvvdpMapMean(result.map, inside), 20.0 * cvvdpMapMean(result.map, outside));
    EXPECT_TRUE(std::isnan(cvvdpMapMean(result.map, cv::Mat::zeros(256, 256, CV_8UC1))));
}

TEST(Cvvdp, JodMappingIsContinuousAtTheThreshold) {
    EXPECT_EQ(cvvdpQualityToJod(0.0), 10.0);
    EXPECT_NEAR(cvvdpQualityToJod(0.1 - 1e-12), cvvdpQualityToJod(0.1 + 1e-12), 1e-9);
    EXPECT_LT(cvvdpQualityToJod(2.0), cvvdpQualityToJod(1.0));
}

TEST(Cvvdp, BlurLowersTheScore) {
    const cv::Mat image = texturedImage(320, 200);
    const CvvdpResult result = cvvdp(image, blurred(image, 2.0), cvvdpDisplay("standard_fhd"));
    EXPECT_LT(result.jod, 10.0);
    EXPECT_GT(result.jod, 0.0);
}

} // namespace
