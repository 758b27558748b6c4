// PSNR and SSIM through OpenCV's quality module, checked against values computed by hand (docs/metrics.md).
#include "analysis/metrics/image_quality.h"

#include <gtest/gtest.h>

#include <cmath>

namespace skinlab::metrics {
namespace {

// SSIM of two flat images: variances and covariance vanish, so SSIM = (2·μx·μy + C1)/(μx² + μy² + C1) with
// C1 = (0.01·255)² = 6.5025: (2·128·138 + 6.5025)/(128² + 138² + 6.5025) = 0.99717790...
TEST(ImageQuality, SsimOfFlat128AgainstFlat138) {
    cv::Mat a(64, 64, CV_64FC3, cv::Scalar::all(128.0));
    cv::Mat b(64, 64, CV_64FC3, cv::Scalar::all(138.0));
    double ssim = structuralSimilarity(structuralSimilarityMap(a, b));
    EXPECT_NEAR(ssim, 0.9971779, 1e-7);
    EXPECT_NEAR(ssim, (2.0 * 128 * 138 + 6.5025) / (128.0 * 128 + 138.0 * 138 + 6.5025), 1e-12);
}

// MSE 100 (a uniform offset of 10) with peak 255: 10·log10(255²/100) = 28.1308 dB.
TEST(ImageQuality, PsnrAtMse100) {
    cv::Mat a(32, 48, CV_64FC3, cv::Scalar(100.0, 50.0, 20.0));
    cv::Mat b = a + cv::Scalar::all(10.0);
    EXPECT_NEAR(peakSignalToNoiseRatio(a, b), 28.1308, 1e-4);
    cv::Mat mask = cv::Mat::zeros(32, 48, CV_8UC1);
    mask(cv::Rect(0, 0, 10, 10)).setTo(255);
    EXPECT_NEAR(peakSignalToNoiseRatio(a, b, mask), 28.1308, 1e-4);
}

// The MSE is pooled over channels: an error of 10 in one channel of three is MSE 100/3.
TEST(ImageQuality, PsnrPoolsTheChannels) {
    cv::Mat a(16, 16, CV_64FC3, cv::Scalar::all(60.0));
    cv::Mat b = a + cv::Scalar(10.0, 0.0, 0.0);
    EXPECT_NEAR(peakSignalToNoiseRatio(a, b), 10.0 * std::log10(255.0 * 255.0 * 3.0 / 100.0), 1e-9);
}

TEST(ImageQuality, IdenticalImagesScoreInfinitePsnrAndSsimOne) {
    cv::Mat a(40, 40, CV_64FC3);
    cv::randu(a, 0.0, 255.0);
    EXPECT_TRUE(std::isinf(peakSignalToNoiseRatio(a, a)));
    EXPECT_NEAR(structuralSimilarity(structuralSimilarityMap(a, a)), 1.0, 1e-12);
}

// The masked PSNR only sees the masked pixels: an error outside the mask leaves it infinite.
TEST(ImageQuality, MaskedScoresIgnoreOtherPixels) {
    cv::Mat a(20, 20, CV_64FC3, cv::Scalar::all(90.0));
    cv::Mat b = a.clone();
    b(cv::Rect(10, 0, 10, 20)).setTo(cv::Scalar::all(200.0));
    cv::Mat left = cv::Mat::zeros(20, 20, CV_8UC1);
    left(cv::Rect(0, 0, 10, 20)).setTo(255);
    EXPECT_TRUE(std::isinf(peakSignalToNoiseRatio(a, b, left)));
    EXPECT_FALSE(std::isinf(peakSignalToNoiseRatio(a, b)));
    EXPECT_TRUE(std::isnan(peakSignalToNoiseRatio(a, b, cv::Mat::zeros(20, 20, CV_8UC1))));
}

} // namespace
} // namespace skinlab::metrics
