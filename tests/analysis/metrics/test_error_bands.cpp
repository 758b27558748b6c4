// Band construction (docs/metrics.md) on analytic scenes whose bands are known in closed form.
#include "analysis/metrics/error_bands.h"

#include "synthetic_render.h"

#include <gtest/gtest.h>

#include <cmath>

namespace skinlab::metrics {
namespace {

using testing::discPixel;
using testing::DiscScene;
using testing::renderDiscScene;

// Pixels this close (in pixels) to an analytic band boundary may fall either way: point sampling puts the
// rasterised silhouette up to ~0.7 px from the analytic circle, and the edge is taken half a pixel from the
// edge pixels' centres.
constexpr double boundaryTolerance = 1.0;

bool inBand(const ErrorBands& bands, Band band, int x, int y) { return bands.mask(band).at<uint8_t>(y, x) != 0; }

// A skin disc in front of a non-skin far plane: the depth jump at the silhouette is > r_w, so the halo band is
// the ring inside the disc edge of width ρ = r_w·f_px/D_near; the spill band is the ring outside it of the same
// width (ρ of the nearest skin pixel); the interior is the disc farther than 2ρ from its edge; no bleed.
TEST(ErrorBands, DiscInFrontOfFarPlaneHasAHaloRingOfWidthRho) {
    DiscScene scene;
    scene.size = 256;
    testing::SyntheticRender render = renderDiscScene(scene);
    BandGeometry geometry{0.008, render.focalLengthPixels}; // r_w = 8 mm in metres
    ErrorBands bands = buildErrorBands(render.depth, render.mask, geometry);

    const double rho = geometry.supportRadiusWorld * geometry.focalLengthPixels / scene.nearDepth;
    const double discRadiusPixels = scene.discRadius * geometry.focalLengthPixels / scene.nearDepth;
    ASSERT_GT(rho, 3.0) << "the test needs a band several pixels wide";
    int checkedHalo = 0, checkedSpill = 0, checkedInterior = 0;
    for (int y = 0; y < scene.size; ++y)
        for (int x = 0; x < scene.size; ++x) {
            testing::DiscPixel pixel = discPixel(scene, x, y);
            double fromEdge = std::fabs(discRadiusPixels - pixel.screenRadius);
            ASSERT_FALSE(inBand(bands, Band::bleed, x, y)) << "no material edge in this scene";
            if (pixel.onDisc) {
                ASSERT_FALSE(inBand(bands, Band::spill, x, y));
                ASSERT_NEAR(bands.projectedRadius.at<float>(y, x), rho, 1e-4 * rho);
                if (fromEdge < rho - boundaryTolerance) {
                    ASSERT_TRUE(inBand(bands, Band::halo, x, y)) << x << "," << y << " is " << fromEdge << " px inside";
                    ++checkedHalo;
                }
                if (fromEdge > rho + boundaryTolerance) {
                    ASSERT_FALSE(inBand(bands, Band::halo, x, y)) << x << "," << y;
                }
                if (fromEdge > 2 * rho + boundaryTolerance) {
                    ASSERT_TRUE(inBand(bands, Band::interior, x, y)) << x << "," << y;
                    ++checkedInterior;
                }
                if (fromEdge < 2 * rho - boundaryTolerance) {
                    ASSERT_FALSE(inBand(bands, Band::interior, x, y));
                }
            } else {
                ASSERT_FALSE(inBand(bands, Band::halo, x, y));
                ASSERT_FALSE(inBand(bands, Band::interior, x, y));
                if (fromEdge < rho - boundaryTolerance) {
                    ASSERT_TRUE(inBand(bands, Band::spill, x, y)) << x << "," << y;
                    ++checkedSpill;
                }
                if (fromEdge > rho + boundaryTolerance) {
                    ASSERT_FALSE(inBand(bands, Band::spill, x, y));
                }
            }
        }
    EXPECT_GT(checkedHalo, 500);
    EXPECT_GT(checkedSpill, 500);
    EXPECT_GT(checkedInterior, 1000);
    // Area of the ring, within the boundary uncertainty of one perimeter's worth of pixels.
    double ringArea =
        M_PI * (discRadiusPixels * discRadiusPixels - (discRadiusPixels - rho) * (discRadiusPixels - rho));
    EXPECT_NEAR(cv::countNonZero(bands.mask(Band::halo)), ringArea, 2 * M_PI * discRadiusPixels);
}

// Both sides skin: the far plane's pixels next to the silhouette are halo too, each with its own ρ (smaller,
// since the plane is farther).
TEST(ErrorBands, SkinOnBothSidesOfADepthEdgeGivesHaloOnBothSides) {
    DiscScene scene;
    scene.size = 256;
    scene.farPlaneIsSkin = true;
    testing::SyntheticRender render = renderDiscScene(scene);
    BandGeometry geometry{0.008, render.focalLengthPixels};
    ErrorBands bands = buildErrorBands(render.depth, render.mask, geometry);
    const double rhoFar = geometry.supportRadiusWorld * geometry.focalLengthPixels / scene.farDepth;
    const double discRadiusPixels = scene.discRadius * geometry.focalLengthPixels / scene.nearDepth;
    int checked = 0;
    for (int y = 0; y < scene.size; ++y)
        for (int x = 0; x < scene.size; ++x) {
            testing::DiscPixel pixel = discPixel(scene, x, y);
            if (pixel.onDisc) continue;
            double fromEdge = pixel.screenRadius - discRadiusPixels;
            if (fromEdge < rhoFar - boundaryTolerance) {
                ASSERT_TRUE(inBand(bands, Band::halo, x, y)) << x << "," << y;
                ++checked;
            }
            if (fromEdge > rhoFar + boundaryTolerance) {
                ASSERT_FALSE(inBand(bands, Band::halo, x, y)) << x << "," << y;
            }
            ASSERT_FALSE(inBand(bands, Band::spill, x, y)) << "skin is never spill";
        }
    EXPECT_GT(checked, 300);
}

// A material edge: a flat plane at one depth, skin on the left half, non-skin on the right. The bleed band is
// exactly the skin columns whose centre lies within ρ of the boundary (the boundary between two pixel columns is
// where the distance is measured from), the spill band the same on the other side; no halo.
TEST(ErrorBands, MaterialEdgeAtContinuousDepthGivesABleedBand) {
    const int size = 128;
    const float depthValue = 2.0f;
    cv::Mat depth(size, size, CV_32FC1, cv::Scalar(depthValue));
    cv::Mat mask = cv::Mat::zeros(size, size, CV_32FC1);
    mask(cv::Rect(0, 0, size / 2, size)).setTo(1.0f);
    BandGeometry geometry{0.01, 1000.0}; // ρ = 0.01·1000/2 = 5 px
    ErrorBands bands = buildErrorBands(depth, mask, geometry);
    const double rho = 5.0;
    EXPECT_EQ(cv::countNonZero(bands.mask(Band::halo)), 0);
    EXPECT_EQ(cv::countNonZero(bands.depthEdges), 0);
    for (int x = 0; x < size; ++x) {
        double fromBoundary = std::fabs(size / 2.0 - (x + 0.5));
        bool skin = x < size / 2;
        for (int y : {0, size / 2, size - 1}) {
            EXPECT_EQ(inBand(bands, Band::bleed, x, y), skin && fromBoundary <= rho) << x;
            EXPECT_EQ(inBand(bands, Band::spill, x, y), !skin && fromBoundary <= rho) << x;
            EXPECT_EQ(inBand(bands, Band::interior, x, y), skin && fromBoundary > 2 * rho) << x;
        }
    }
    EXPECT_EQ(cv::countNonZero(bands.mask(Band::bleed)), 5 * size);
}

// A depth step inside one material is a depth edge only when it exceeds r_w: a step of 0.5·r_w is continuous
// (no band), 1.5·r_w is an edge (halo on both sides).
TEST(ErrorBands, DepthStepsBelowTheKernelRadiusAreNotEdges) {
    const int size = 64;
    BandGeometry geometry{0.01, 500.0};
    for (double step : {0.005, 0.015}) {
        cv::Mat depth(size, size, CV_32FC1, cv::Scalar(1.0f));
        depth(cv::Rect(size / 2, 0, size / 2, size)).setTo(static_cast<float>(1.0 + step));
        cv::Mat mask(size, size, CV_32FC1, cv::Scalar(1.0f));
        ErrorBands bands = buildErrorBands(depth, mask, geometry);
        if (step > geometry.supportRadiusWorld) {
            // ρ = 5 px on the near side (columns 27..31), 4.93 px on the far side (columns 32..36).
            EXPECT_EQ(cv::countNonZero(bands.mask(Band::halo)), 10 * size) << "step " << step;
        } else {
            EXPECT_EQ(cv::countNonZero(bands.mask(Band::halo)), 0) << "step " << step;
            EXPECT_EQ(cv::countNonZero(bands.mask(Band::interior)), size * size) << "step " << step;
        }
    }
}

TEST(ErrorBands, BandsAreDisjoint) {
    DiscScene scene;
    scene.size = 200;
    scene.farPlaneIsSkin = true;
    scene.stripeHalfWidth = 0.02;
    testing::SyntheticRender render = renderDiscScene(scene);
    ErrorBands bands = buildErrorBands(render.depth, render.mask, {0.008, render.focalLengthPixels});
    for (Band a : allBands)
        for (Band b : allBands)
            if (a != b) {
                cv::Mat both;
                cv::bitwise_and(bands.mask(a), bands.mask(b), both);
                EXPECT_EQ(cv::countNonZero(both), 0) << bandName(a) << " and " << bandName(b);
            }
    EXPECT_GT(cv::countNonZero(bands.mask(Band::bleed)), 0);
    EXPECT_GT(cv::countNonZero(bands.mask(Band::spill)), 0);
}

} // namespace
} // namespace skinlab::metrics
