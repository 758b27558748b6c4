#pragma once
// Exact Euclidean distance transform with the nearest feature pixel (P. F. Felzenszwalb, D. P. Huttenlocher,
// "Distance transforms of sampled functions", Theory of Computing 8, 2012: lower envelope of parabolas, one 1-D
// pass per column then one per row). Distances are between pixel centres, in pixels.
#include <opencv2/core.hpp>

namespace skinlab::metrics {

struct DistanceField {
    cv::Mat distance; // CV_32FC1: distance to the nearest feature pixel; +inf when the image has no feature
    cv::Mat nearest;  // CV_32SC1: row-major index y·width + x of that feature pixel; −1 when there is none
};

// `features`: CV_8UC1, non-zero marks a feature pixel.
DistanceField euclideanDistanceTransform(const cv::Mat& features);

} // namespace skinlab::metrics
