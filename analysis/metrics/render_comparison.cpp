#include "analysis/metrics/render_comparison.h"

#include "analysis/metrics/ciede2000.h"
#include "analysis/metrics/colour_space.h"
#include "analysis/metrics/image_quality.h"
#include "common/error.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

namespace skinlab::metrics {
namespace {

constexpr double notANumber = std::numeric_limits<double>::quiet_NaN();

std::string formatNumber(double value) {
    std::ostringstream out;
    out.precision(9);
    out << value;
    return out.str();
}

std::string sizeText(int width, int height) { return std::to_string(width) + "x" + std::to_string(height); }

struct EncodedImage {
    cv::Mat lab;       // CV_64FC3
    cv::Mat luminance; // CV_64FC1
    cv::Mat display;   // CV_64FC3 on 0–255
};

EncodedImage encode(const cv::Mat& beauty, double exposure) {
    EncodedImage encoded;
    encoded.lab.create(beauty.size(), CV_64FC3);
    encoded.luminance.create(beauty.size(), CV_64FC1);
    encoded.display.create(beauty.size(), CV_64FC3);
    for (int y = 0; y < beauty.rows; ++y) {
        const auto* in = beauty.ptr<cv::Vec3f>(y);
        auto* lab = encoded.lab.ptr<cv::Vec3d>(y);
        auto* luminance = encoded.luminance.ptr<double>(y);
        auto* display = encoded.display.ptr<cv::Vec3d>(y);
        for (int x = 0; x < beauty.cols; ++x) {
            double r = in[x][0], g = in[x][1], b = in[x][2];
            Lab value = displayLab(r, g, b, exposure);
            lab[x] = {value.lightness, value.a, value.b};
            double y709 = luminanceRec709(r, g, b) * exposure;
            luminance[x] = std::isfinite(y709) ? y709 : 0.0;
            display[x] = {255.0 * encodeSrgb(r * exposure), 255.0 * encodeSrgb(g * exposure),
                          255.0 * encodeSrgb(b * exposure)};
        }
    }
    return encoded;
}

// ΔE00 values where `mask` is set (all pixels when empty).
std::vector<double> collect(const cv::Mat& deltaE, const cv::Mat& mask) {
    std::vector<double> values;
    for (int y = 0; y < deltaE.rows; ++y) {
        const auto* row = deltaE.ptr<float>(y);
        const uint8_t* selected = mask.empty() ? nullptr : mask.ptr<uint8_t>(y);
        for (int x = 0; x < deltaE.cols; ++x)
            if (!selected || selected[x]) values.push_back(row[x]);
    }
    return values;
}

// Σ of a CV_64FC1 image over the pixels where the CV_8UC1 mask is set.
double maskedSum(const cv::Mat& values, const cv::Mat& mask) {
    double sum = 0.0;
    for (int y = 0; y < values.rows; ++y) {
        const auto* row = values.ptr<double>(y);
        const auto* selected = mask.ptr<uint8_t>(y);
        for (int x = 0; x < values.cols; ++x)
            if (selected[x]) sum += row[x];
    }
    return sum;
}

double mean(const std::vector<double>& values) {
    if (values.empty()) return notANumber;
    double sum = 0.0;
    for (double v : values) sum += v;
    return sum / static_cast<double>(values.size());
}

} // namespace

double percentile95(std::vector<double> values) {
    if (values.empty()) return notANumber;
    double position = 0.95 * static_cast<double>(values.size() - 1);
    auto lower = static_cast<std::size_t>(std::floor(position));
    // Selection instead of a full sort: the lower order statistic, then the smallest value above it.
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(lower), values.end());
    double lowerValue = values[lower];
    double upperValue = lowerValue;
    if (lower + 1 < values.size())
        upperValue = *std::min_element(values.begin() + static_cast<std::ptrdiff_t>(lower) + 1, values.end());
    double fraction = position - static_cast<double>(lower);
    return lowerValue + fraction * (upperValue - lowerValue);
}

void validateMetricOptions(const MetricOptions& options) {
    if (!(options.exposure > 0.0) || !std::isfinite(options.exposure))
        throwInput("--exposure", "", formatNumber(options.exposure) + " must be a positive number");
    if (options.sssRadiusMillimetres &&
        (!(*options.sssRadiusMillimetres > 0.0) || !std::isfinite(*options.sssRadiusMillimetres)))
        throwInput("--sss-radius-mm", "", formatNumber(*options.sssRadiusMillimetres) + " must be a positive number");
    if (!(options.pixelsPerDegree > 0.0) || !std::isfinite(options.pixelsPerDegree))
        throwInput("--ppd", "", formatNumber(options.pixelsPerDegree) + " must be a positive number");
}

PreparedReference prepareReference(MetricRender reference, const MetricOptions& options) {
    const std::string file = reference.path.string();
    validateMetricOptions(options);
    if (reference.plain) {
        PreparedReference prepared;
        for (cv::Mat& mask : prepared.bands.masks) mask = cv::Mat::zeros(reference.height, reference.width, CV_8UC1);
        prepared.bands.skin = cv::Mat::zeros(reference.height, reference.width, CV_8UC1);
        EncodedImage encoded = encode(reference.beauty, options.exposure);
        prepared.lab = std::move(encoded.lab);
        prepared.luminance = std::move(encoded.luminance);
        prepared.display = std::move(encoded.display);
        prepared.render = std::move(reference);
        return prepared;
    }
    if (reference.depth.empty() || reference.mask.empty() || !reference.focalLengthPixels ||
        !reference.millimetresPerUnit)
        throw std::logic_error("prepareReference(): " + file + " was not loaded as a reference");
    PreparedReference prepared;
    if (options.sssRadiusMillimetres) {
        prepared.sssRadiusMillimetres = *options.sssRadiusMillimetres;
    } else {
        if (!reference.sssRadiusMillimetres) throwInput(file, "skinlab:sss_radius_mm", "metadata attribute is missing");
        prepared.sssRadiusMillimetres = *reference.sssRadiusMillimetres;
    }
    // r_w = sss_radius_mm / mm_per_unit (contract 1).
    prepared.geometry.supportRadiusWorld = prepared.sssRadiusMillimetres / *reference.millimetresPerUnit;
    prepared.geometry.focalLengthPixels = *reference.focalLengthPixels;
    prepared.bands = buildErrorBands(reference.depth, reference.mask, prepared.geometry);
    EncodedImage encoded = encode(reference.beauty, options.exposure);
    prepared.lab = std::move(encoded.lab);
    prepared.luminance = std::move(encoded.luminance);
    prepared.display = std::move(encoded.display);
    prepared.skinLuminanceSum = maskedSum(prepared.luminance, prepared.bands.skin);
    prepared.render = std::move(reference);
    return prepared;
}

void checkComparable(const MetricRender& ref, const MetricRender& test) {
    if (test.width != ref.width || test.height != ref.height)
        throwInput(test.path.string(), "",
                   "size " + sizeText(test.width, test.height) + " differs from the reference " + ref.path.string() +
                       " (" + sizeText(ref.width, ref.height) + ")");
    if (test.focalLengthPixels && ref.focalLengthPixels) {
        double relative = std::fabs(*test.focalLengthPixels - *ref.focalLengthPixels) / *ref.focalLengthPixels;
        // 1e-5 relative: float32 metadata written from the same camera agrees to rounding.
        if (relative > 1e-5)
            throwInput(test.path.string(), "skinlab:f_px",
                       formatNumber(*test.focalLengthPixels) + " differs from the reference's " +
                           formatNumber(*ref.focalLengthPixels) + " (not the same camera)");
    }
}

ComparisonResult compareWithReference(const PreparedReference& reference, const MetricRender& test,
                                      const MetricOptions& options) {
    const MetricRender& ref = reference.render;
    checkComparable(ref, test);

    EncodedImage encoded = encode(test.beauty, options.exposure);
    ComparisonResult result;
    result.deltaE00.create(ref.height, ref.width, CV_32FC1);
    cv::Mat absoluteLuminance(ref.height, ref.width, CV_64FC1);
    for (int y = 0; y < ref.height; ++y) {
        const auto* labReference = reference.lab.ptr<cv::Vec3d>(y);
        const auto* labTest = encoded.lab.ptr<cv::Vec3d>(y);
        const auto* yReference = reference.luminance.ptr<double>(y);
        const auto* yTest = encoded.luminance.ptr<double>(y);
        auto* deltaE = result.deltaE00.ptr<float>(y);
        auto* leak = absoluteLuminance.ptr<double>(y);
        for (int x = 0; x < ref.width; ++x) {
            deltaE[x] = static_cast<float>(ciede2000({labReference[x][0], labReference[x][1], labReference[x][2]},
                                                     {labTest[x][0], labTest[x][1], labTest[x][2]}));
            leak[x] = std::fabs(yTest[x] - yReference[x]);
        }
    }

    cv::Mat ssimMap = structuralSimilarityMap(reference.display, encoded.display);
    result.flip = flipErrorMap(ref.beauty, test.beauty, options.pixelsPerDegree, options.exposure);
    {
        const bool scaled = options.exposure != 1.0;
        const CvvdpResult visibility =
            cvvdp(scaled ? cv::Mat(ref.beauty * options.exposure) : ref.beauty,
                  scaled ? cv::Mat(test.beauty * options.exposure) : test.beauty, options.display, true);
        result.cvvdpJod = visibility.jod;
        result.cvvdpMap = visibility.map;
    }
    const cv::Mat& skin = reference.bands.skin;
    const auto totalPixels = static_cast<std::size_t>(ref.width) * static_cast<std::size_t>(ref.height);
    const auto skinPixels = static_cast<std::size_t>(cv::countNonZero(skin));

    auto regionScores = [&](const cv::Mat& mask) {
        RegionScores scores;
        std::vector<double> values = collect(result.deltaE00, mask);
        scores.pixels = values.size();
        scores.psnrDecibels = peakSignalToNoiseRatio(reference.display, encoded.display, mask);
        scores.ssim = structuralSimilarity(ssimMap, mask);
        scores.deltaE00Mean = mean(values);
        scores.deltaE00P95 = percentile95(std::move(values));
        scores.flipMean = flipMean(result.flip, mask);
        scores.cvvdpMapMean = cvvdpMapMean(result.cvvdpMap, mask);
        return scores;
    };
    result.image = regionScores(cv::Mat());
    if (ref.plain) {
        // No skin mask and no depth: the skin region and the bands are undefined.
        result.bandsMeasured = false;
        result.skin = {0, notANumber, notANumber, notANumber, notANumber, notANumber, notANumber};
        for (auto& scores : result.bands)
            scores = {0,          notANumber, notANumber, notANumber, notANumber,
                      notANumber, notANumber, notANumber, notANumber};
        return result;
    }
    result.skin = regionScores(skin);

    for (Band band : allBands) {
        const cv::Mat& mask = reference.bands.mask(band);
        BandScores& scores = result.bands[static_cast<std::size_t>(band)];
        std::vector<double> values = collect(result.deltaE00, mask);
        scores.pixels = values.size();
        scores.fractionOfImage = static_cast<double>(scores.pixels) / static_cast<double>(totalPixels);
        scores.fractionOfSkin =
            skinPixels ? static_cast<double>(scores.pixels) / static_cast<double>(skinPixels) : notANumber;
        scores.deltaE00Mean = mean(values);
        scores.deltaE00P95 = percentile95(std::move(values));
        scores.flipMean = flipMean(result.flip, mask);
        scores.cvvdpMapMean = cvvdpMapMean(result.cvvdpMap, mask);
        double leakSum = maskedSum(absoluteLuminance, mask);
        scores.leakEnergy = reference.skinLuminanceSum > 0.0 ? leakSum / reference.skinLuminanceSum : notANumber;
    }
    double interiorMean = result.band(Band::interior).deltaE00Mean;
    for (auto& scores : result.bands) scores.excess = scores.deltaE00Mean - interiorMean; // NaN propagates
    return result;
}

} // namespace skinlab::metrics
