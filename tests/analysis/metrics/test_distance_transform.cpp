// The exact Euclidean distance transform against brute force.
#include "analysis/metrics/distance_transform.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace skinlab::metrics {
namespace {

TEST(DistanceTransform, MatchesBruteForceOnRandomFeatures) {
    std::mt19937 random(7);
    for (double density : {0.002, 0.02, 0.3}) {
        cv::Mat features = cv::Mat::zeros(37, 53, CV_8UC1);
        std::bernoulli_distribution pick(density);
        for (int y = 0; y < features.rows; ++y)
            for (int x = 0; x < features.cols; ++x)
                if (pick(random)) features.at<uint8_t>(y, x) = 1;
        features.at<uint8_t>(5, 5) = 1; // at least one
        DistanceField field = euclideanDistanceTransform(features);
        for (int y = 0; y < features.rows; ++y)
            for (int x = 0; x < features.cols; ++x) {
                double best = std::numeric_limits<double>::infinity();
                for (int fy = 0; fy < features.rows; ++fy)
                    for (int fx = 0; fx < features.cols; ++fx)
                        if (features.at<uint8_t>(fy, fx)) best = std::min(best, std::hypot(fx - x, fy - y));
                ASSERT_NEAR(field.distance.at<float>(y, x), best, 1e-4)
                    << "density " << density << " at " << x << "," << y;
                int nearest = field.nearest.at<int>(y, x);
                int nx = nearest % features.cols;
                int ny = nearest / features.cols;
                ASSERT_TRUE(features.at<uint8_t>(ny, nx)) << "nearest index is not a feature";
                ASSERT_NEAR(std::hypot(nx - x, ny - y), best, 1e-4);
            }
    }
}

TEST(DistanceTransform, NoFeatureGivesInfinityAndNoIndex) {
    DistanceField field = euclideanDistanceTransform(cv::Mat::zeros(4, 6, CV_8UC1));
    EXPECT_TRUE(std::isinf(field.distance.at<float>(2, 3)));
    EXPECT_EQ(field.nearest.at<int>(2, 3), -1);
}

} // namespace
} // namespace skinlab::metrics
