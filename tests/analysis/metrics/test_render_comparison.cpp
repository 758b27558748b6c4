// Comparisons of synthetic renders read back from EXR files: identity, known errors, resolution independence.
#include "analysis/metrics/ciede2000.h"
#include "analysis/metrics/colour_space.h"
#include "analysis/metrics/render_comparison.h"

#include "synthetic_render.h"
#include "tests/common/temp_folder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

namespace skinlab::metrics {
namespace {
namespace fs = std::filesystem;
using testing::DiscScene;
using testing::SyntheticRender;

// Writes both renders as EXR and compares them through the file path a user's renders take.
ComparisonResult compareFiles(const fs::path& folder, const SyntheticRender& reference, const SyntheticRender& test,
                              const MetricOptions& options = {}) {
    testing::writeSyntheticExr(folder / "reference.exr", reference);
    testing::writeSyntheticExr(folder / "test.exr", test);
    PreparedReference prepared =
        prepareReference(loadMetricRender(folder / "reference.exr", RenderRole::reference), options);
    return compareWithReference(prepared, loadMetricRender(folder / "test.exr", RenderRole::test), options);
}

DiscScene sceneWithEveryBand(int size) {
    DiscScene scene;
    scene.size = size;
    scene.farPlaneIsSkin = true;  // halo on both sides of the silhouette
    scene.stripeHalfWidth = 0.02; // a non-skin stripe across the disc: bleed and spill
    return scene;
}

TEST(RenderComparison, IdenticalRendersScoreZeroEverywhere) {
    const test_support::TempFolder folder;
    SyntheticRender render = testing::renderDiscScene(sceneWithEveryBand(160));
    ComparisonResult result = compareFiles(folder.path(), render, render);
    EXPECT_EQ(cv::countNonZero(result.deltaE00), 0);
    for (const RegionScores* region : {&result.image, &result.skin}) {
        EXPECT_TRUE(std::isinf(region->psnrDecibels));
        EXPECT_DOUBLE_EQ(region->ssim, 1.0);
        EXPECT_EQ(region->deltaE00Mean, 0.0);
        EXPECT_EQ(region->deltaE00P95, 0.0);
    }
    for (Band band : allBands) {
        const BandScores& scores = result.band(band);
        EXPECT_GT(scores.pixels, 0u) << bandName(band) << " band is empty: the test would not test it";
        EXPECT_EQ(scores.deltaE00Mean, 0.0) << bandName(band);
        EXPECT_EQ(scores.deltaE00P95, 0.0) << bandName(band);
        EXPECT_EQ(scores.excess, 0.0) << bandName(band);
        EXPECT_EQ(scores.leakEnergy, 0.0) << bandName(band);
    }
}

// Every skin pixel brightened by 0.05 (all channels): each skin band's ΔE00 is the ΔE00 of that one colour change,
// the excess over the interior is 0, the spill band (non-skin) is untouched, and the leak energy of a band is
// 0.05·N_band / (N_skin·Y_skin), because the RGB→Y row sums to 1.
TEST(RenderComparison, UniformSkinChangeGivesKnownScores) {
    const test_support::TempFolder folder;
    SyntheticRender reference = testing::renderDiscScene(sceneWithEveryBand(160));
    SyntheticRender test = reference;
    test.beauty = reference.beauty.clone();
    for (int y = 0; y < test.height; ++y)
        for (int x = 0; x < test.width; ++x)
            if (reference.mask.at<float>(y, x) >= 0.5f)
                test.beauty.at<cv::Vec3f>(y, x) += cv::Vec3f(0.05f, 0.05f, 0.05f);
    ComparisonResult result = compareFiles(folder.path(), reference, test);

    const cv::Vec3f skinColour(0.6f, 0.4f, 0.3f); // renderDiscScene's skin
    const cv::Vec3f farColour(0.3f, 0.3f, 0.35f); // the far plane, skin here too
    auto changeOf = [](cv::Vec3f c) {
        return ciede2000(displayLab(c[0], c[1], c[2], 1.0), displayLab(c[0] + 0.05f, c[1] + 0.05f, c[2] + 0.05f, 1.0));
    };
    const auto skinPixels = static_cast<double>(result.skin.pixels);
    double skinLuminanceSum = 0.0;
    for (int y = 0; y < reference.height; ++y)
        for (int x = 0; x < reference.width; ++x)
            if (reference.mask.at<float>(y, x) >= 0.5f) {
                cv::Vec3f c = reference.beauty.at<cv::Vec3f>(y, x);
                skinLuminanceSum += luminanceRec709(c[0], c[1], c[2]);
            }
    for (Band band : {Band::halo, Band::bleed, Band::interior}) {
        const BandScores& scores = result.band(band);
        EXPECT_GE(scores.deltaE00Mean, std::min(changeOf(skinColour), changeOf(farColour)) - 1e-5) << bandName(band);
        EXPECT_LE(scores.deltaE00Mean, std::max(changeOf(skinColour), changeOf(farColour)) + 1e-5) << bandName(band);
        EXPECT_NEAR(scores.leakEnergy, 0.05 * scores.pixels / skinLuminanceSum, 1e-5) << bandName(band);
        EXPECT_NEAR(scores.fractionOfSkin, scores.pixels / skinPixels, 1e-12);
    }
    // The bleed band lies on the disc only, so its ΔE00 is exactly the disc colour's.
    EXPECT_NEAR(result.band(Band::bleed).deltaE00Mean, changeOf(skinColour), 1e-5);
    EXPECT_NEAR(result.band(Band::bleed).deltaE00P95, changeOf(skinColour), 1e-5);
    EXPECT_EQ(result.band(Band::spill).deltaE00Mean, 0.0);
    EXPECT_EQ(result.band(Band::spill).leakEnergy, 0.0);
    EXPECT_GT(result.skin.deltaE00Mean, 0.5);
    EXPECT_LT(result.image.deltaE00Mean, result.skin.deltaE00Mean); // the stripe is unchanged
}

// Adds a synthetic screen-space error of *physical* width w (world units, on the surface it lands on) next to every
// depth edge (halo: both sides of the silhouette) and every material edge (bleed on the skin side, spill on the
// stripe), fading linearly to zero at w. The same physical error at any resolution.
SyntheticRender withEdgeErrors(const DiscScene& scene, const SyntheticRender& reference, double width) {
    SyntheticRender test = reference;
    test.beauty = reference.beauty.clone();
    const double silhouetteOnFarPlane = scene.discRadius * scene.farDepth / scene.nearDepth;
    for (int y = 0; y < scene.size; ++y)
        for (int x = 0; x < scene.size; ++x) {
            testing::DiscPixel pixel = testing::discPixel(scene, x, y);
            double radial = std::hypot(pixel.worldX, pixel.worldY);
            double add = 0.0;
            if (pixel.onDisc) {
                double fromRim = scene.discRadius - radial;
                if (fromRim < width) add += 0.10 * (1.0 - fromRim / width);
                double fromStripe = std::fabs(std::fabs(pixel.worldY) - scene.stripeHalfWidth);
                if (fromStripe < width) add += 0.05 * (1.0 - fromStripe / width);
            } else {
                double fromSilhouette = radial - silhouetteOnFarPlane;
                if (fromSilhouette < width) add += 0.10 * (1.0 - fromSilhouette / width);
            }
            test.beauty.at<cv::Vec3f>(y, x) += cv::Vec3f::all(static_cast<float>(add));
        }
    return test;
}

// docs/metrics.md: energy scores agree within 5% between 512² and 1024² renders of the same scene.
TEST(RenderComparison, LeakEnergiesAreResolutionIndependent) {
    const test_support::TempFolder folder;
    const double errorWidth = 0.8 * 0.008; // 80% of r_w = 8 mm, so the error lies inside the bands
    BandScores scores[2][4];
    double haloFraction[2] = {};
    int index = 0;
    for (int size : {512, 1024}) {
        DiscScene scene = sceneWithEveryBand(size);
        SyntheticRender reference = testing::renderDiscScene(scene);
        ComparisonResult result = compareFiles(folder.path(), reference, withEdgeErrors(scene, reference, errorWidth));
        for (Band band : allBands) scores[index][static_cast<size_t>(band)] = result.band(band);
        haloFraction[index] = result.band(Band::halo).fractionOfImage;
        ++index;
    }
    for (Band band : {Band::halo, Band::bleed, Band::spill}) {
        double low = scores[0][static_cast<size_t>(band)].leakEnergy;
        double high = scores[1][static_cast<size_t>(band)].leakEnergy;
        EXPECT_GT(low, 1e-4) << bandName(band) << ": the synthetic error must reach this band";
        EXPECT_NEAR(low / high, 1.0, 0.05) << bandName(band) << " leak energy 512²: " << low << ", 1024²: " << high;
        std::printf("%s leak energy 512^2 %.6g 1024^2 %.6g (ratio %.4f)\n", std::string(bandName(band)).c_str(), low,
                    high, low / high);
        // The band covers the same fraction of the picture at both sizes, up to pixel quantisation: a straight
        // band of width ρ counts round(ρ) pixels across, so its area is off by up to 0.5/ρ (6.5% at ρ = 7.6 px, the
        // 512² render). The leak energy does not inherit this because the error fades out inside the band.
        EXPECT_NEAR(scores[0][static_cast<size_t>(band)].fractionOfImage /
                        scores[1][static_cast<size_t>(band)].fractionOfImage,
                    1.0, 0.08)
            << bandName(band);
    }
    // The error stays inside the bands: nothing in the interior.
    EXPECT_EQ(scores[0][static_cast<size_t>(Band::interior)].leakEnergy, 0.0);
    EXPECT_EQ(scores[1][static_cast<size_t>(Band::interior)].leakEnergy, 0.0);
    EXPECT_GT(haloFraction[0], 0.0);
}

TEST(RenderComparison, Percentile95InterpolatesBetweenOrderStatistics) {
    std::vector<double> values;
    for (int i = 0; i <= 100; ++i) values.push_back(100 - i); // 0..100 shuffled order
    EXPECT_DOUBLE_EQ(percentile95(values), 95.0);
    EXPECT_DOUBLE_EQ(percentile95({1.0, 2.0}), 1.95);
    EXPECT_DOUBLE_EQ(percentile95({7.0}), 7.0);
    EXPECT_TRUE(std::isnan(percentile95({})));
}

} // namespace
} // namespace skinlab::metrics
