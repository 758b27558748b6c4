#include "analysis/metrics/image_quality.h"

#include <cmath>
#include <limits>

#include <opencv2/quality/qualitymse.hpp>
#include <opencv2/quality/qualitypsnr.hpp>
#include <opencv2/quality/qualityssim.hpp>

namespace skinlab::metrics {
namespace {
constexpr double peakValue = 255.0; // QualityPSNR::MAX_PIXEL_VALUE_DEFAULT, and the scale SSIM's constants assume
}

double peakSignalToNoiseRatio(const cv::Mat& reference, const cv::Mat& test, const cv::Mat& mask) {
    CV_Assert(reference.size() == test.size() && reference.type() == test.type());
    if (mask.empty()) {
        // Viewing the channels as extra columns pools the MSE over all samples in one QualityPSNR call.
        cv::Mat referenceSamples = reference.reshape(1);
        cv::Mat testSamples = test.reshape(1);
        return cv::quality::QualityPSNR::compute(referenceSamples, testSamples, cv::noArray(), peakValue)[0];
    }
    // Masked: the per-pixel squared-error map of QualityMSE, averaged over the mask; the same dB formula.
    cv::Mat squaredError;
    cv::quality::QualityMSE::compute(reference, test, squaredError);
    int count = cv::countNonZero(mask);
    if (count == 0) return std::numeric_limits<double>::quiet_NaN();
    cv::Scalar perChannel = cv::mean(squaredError, mask);
    double mse = 0.0;
    for (int c = 0; c < reference.channels(); ++c) mse += perChannel[c];
    mse /= reference.channels();
    if (mse == 0.0) return std::numeric_limits<double>::infinity();
    return 10.0 * std::log10(peakValue * peakValue / mse);
}

cv::Mat structuralSimilarityMap(const cv::Mat& reference, const cv::Mat& test) {
    CV_Assert(reference.size() == test.size() && reference.type() == test.type());
    cv::Mat map;
    cv::quality::QualitySSIM::compute(reference, test, map);
    cv::Mat mapDouble;
    map.convertTo(mapDouble, CV_MAKETYPE(CV_64F, map.channels()));
    if (mapDouble.channels() == 1) return mapDouble;
    cv::Mat sum = cv::Mat::zeros(mapDouble.size(), CV_64FC1);
    std::vector<cv::Mat> channels;
    cv::split(mapDouble, channels);
    for (const auto& c : channels) sum += c;
    return sum / static_cast<double>(channels.size());
}

double structuralSimilarity(const cv::Mat& ssimMap, const cv::Mat& mask) {
    if (!mask.empty() && cv::countNonZero(mask) == 0) return std::numeric_limits<double>::quiet_NaN();
    if (mask.empty()) return cv::mean(ssimMap)[0];
    return cv::mean(ssimMap, mask)[0];
}

} // namespace skinlab::metrics
