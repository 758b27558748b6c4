#include "analysis/metrics/render_comparison.h"

#include "analysis/metrics/ciede2000.h"
#include "analysis/metrics/colour_space.h"
#include "analysis/metrics/image_quality.h"
#include "common/error.h"

#include <opencv2/imgproc.hpp>

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
    cv::Mat lab;     // CV_64FC3
    cv::Mat display; // CV_64FC3 on 0–255
};

EncodedImage encode(const cv::Mat& beauty, double exposure) {
    EncodedImage encoded;
    encoded.lab.create(beauty.size(), CV_64FC3);
    encoded.display.create(beauty.size(), CV_64FC3);
    for (int y = 0; y < beauty.rows; ++y) {
        const auto* in = beauty.ptr<cv::Vec3f>(y);
        auto* lab = encoded.lab.ptr<cv::Vec3d>(y);
        auto* display = encoded.display.ptr<cv::Vec3d>(y);
        for (int x = 0; x < beauty.cols; ++x) {
            double r = in[x][0], g = in[x][1], b = in[x][2];
            Lab value = displayLab(r, g, b, exposure);
            lab[x] = {value.lightness, value.a, value.b};
            display[x] = {255.0 * encodeSrgb(r * exposure), 255.0 * encodeSrgb(g * exposure),
                          255.0 * encodeSrgb(b * exposure)};
        }
    }
    return encoded;
}

// Linear Y × exposure of a render, unclipped (non-finite values count as 0).
cv::Mat linearLuminance(const cv::Mat& beauty, double exposure) {
    cv::Mat luminance(beauty.size(), CV_64FC1);
    for (int y = 0; y < beauty.rows; ++y) {
        const auto* in = beauty.ptr<cv::Vec3f>(y);
        auto* out = luminance.ptr<double>(y);
        for (int x = 0; x < beauty.cols; ++x) {
            const double value = luminanceRec709(in[x][0], in[x][1], in[x][2]) * exposure;
            out[x] = std::isfinite(value) ? value : 0.0;
        }
    }
    return luminance;
}

// The bands on an image of `width` × `height` showing the render (a magnified crop: each shown pixel in the band
// of the render pixel it shows).
ErrorBands bandsAtSize(const ErrorBands& bands, int width, int height) {
    if (bands.skin.cols == width && bands.skin.rows == height) return bands;
    ErrorBands scaled;
    const cv::Size size(width, height);
    for (size_t i = 0; i < bands.masks.size(); ++i)
        cv::resize(bands.masks[i], scaled.masks[i], size, 0.0, 0.0, cv::INTER_NEAREST);
    cv::resize(bands.skin, scaled.skin, size, 0.0, 0.0, cv::INTER_NEAREST);
    return scaled;
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
    if (options.pixelsPerDegree < 0.0 || !std::isfinite(options.pixelsPerDegree) ||
        !(options.flipPixelsPerDegree() > 0.0))
        throwInput("--ppd", "", formatNumber(options.pixelsPerDegree) + " must be a positive number");
}

namespace {

// The display-referred encodings (of the presented image when there is one, else of the render × exposure), the
// render's linear luminance and the bands at the display-referred size.
void encodeReference(PreparedReference& prepared, const MetricRender& reference, const MetricRender* presented,
                     const MetricOptions& options) {
    EncodedImage encoded = encode(presented ? presented->beauty : reference.beauty, presented ? 1.0 : options.exposure);
    prepared.lab = std::move(encoded.lab);
    prepared.display = std::move(encoded.display);
    prepared.luminance = linearLuminance(reference.beauty, options.exposure);
    if (presented) prepared.presented = presented->beauty;
    prepared.displayBands = bandsAtSize(prepared.bands, prepared.lab.cols, prepared.lab.rows);
}

} // namespace

PreparedReference prepareReference(MetricRender reference, const MetricOptions& options,
                                   const MetricRender* presented) {
    const std::string file = reference.path.string();
    validateMetricOptions(options);
    if (presented && options.exposure != 1.0)
        throwInput("--exposure", "",
                   formatNumber(options.exposure) + ": the presented images are scored as shown (exposure 1)");
    if (reference.plain) {
        PreparedReference prepared;
        for (cv::Mat& mask : prepared.bands.masks) mask = cv::Mat::zeros(reference.height, reference.width, CV_8UC1);
        prepared.bands.skin = cv::Mat::zeros(reference.height, reference.width, CV_8UC1);
        encodeReference(prepared, reference, presented, options);
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
    encodeReference(prepared, reference, presented, options);
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
                                      const MetricOptions& options, const MetricRender* presented) {
    const MetricRender& ref = reference.render;
    checkComparable(ref, test);
    if (reference.presented.empty() != (presented == nullptr))
        throw std::logic_error("compareWithReference(): a presented image for one of reference and test only");
    if (presented && (presented->width != reference.presented.cols || presented->height != reference.presented.rows))
        throwInput(presented->path.string(), "",
                   "size " + sizeText(presented->width, presented->height) +
                       " differs from the reference's presented image (" +
                       sizeText(reference.presented.cols, reference.presented.rows) + ")");

    // Display-referred: the presented images as shown, or the renders × exposure on the display.
    const double exposure = presented ? 1.0 : options.exposure;
    const cv::Mat& referenceShown = presented ? reference.presented : ref.beauty;
    const cv::Mat& testShown = presented ? presented->beauty : test.beauty;
    const int width = referenceShown.cols, height = referenceShown.rows;
    EncodedImage encoded = encode(testShown, exposure);
    ComparisonResult result;
    result.deltaE00.create(height, width, CV_32FC1);
    for (int y = 0; y < height; ++y) {
        const auto* labReference = reference.lab.ptr<cv::Vec3d>(y);
        const auto* labTest = encoded.lab.ptr<cv::Vec3d>(y);
        auto* deltaE = result.deltaE00.ptr<float>(y);
        for (int x = 0; x < width; ++x)
            deltaE[x] = static_cast<float>(ciede2000({labReference[x][0], labReference[x][1], labReference[x][2]},
                                                     {labTest[x][0], labTest[x][1], labTest[x][2]}));
    }
    // Linear: the renders' luminance, unclipped.
    const cv::Mat testLuminance = linearLuminance(test.beauty, options.exposure);
    cv::Mat absoluteLuminance;
    cv::absdiff(testLuminance, reference.luminance, absoluteLuminance);

    cv::Mat ssimMap = structuralSimilarityMap(reference.display, encoded.display);
    result.flip = flipErrorMap(referenceShown, testShown, options.flipPixelsPerDegree(), exposure);
    {
        const bool scaled = exposure != 1.0;
        const CvvdpResult visibility = cvvdp(scaled ? cv::Mat(referenceShown * exposure) : referenceShown,
                                             scaled ? cv::Mat(testShown * exposure) : testShown, options.display, true);
        result.cvvdpJod = visibility.jod;
        result.cvvdpMap = visibility.map;
    }
    const cv::Mat& skin = reference.displayBands.skin;
    const auto totalPixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
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
        const cv::Mat& mask = reference.displayBands.mask(band);
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
        double leakSum = maskedSum(absoluteLuminance, reference.bands.mask(band));
        scores.leakEnergy = reference.skinLuminanceSum > 0.0 ? leakSum / reference.skinLuminanceSum : notANumber;
    }
    double interiorMean = result.band(Band::interior).deltaE00Mean;
    for (auto& scores : result.bands) scores.excess = scores.deltaE00Mean - interiorMean; // NaN propagates
    return result;
}

} // namespace skinlab::metrics
