#include "analysis/metrics/error_heatmap.h"

#include "common/error.h"
#include "common/files.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace skinlab::metrics {
namespace {

// Outline colours (BGR), chosen to stand apart from the black-purple-orange-yellow inferno ramp.
cv::Scalar bandColour(Band band) {
    switch (band) {
    case Band::halo: return {255, 255, 0};       // cyan
    case Band::bleed: return {0, 255, 0};        // green
    case Band::spill: return {255, 96, 0};       // blue
    case Band::interior: return {255, 255, 255}; // white
    }
    return {128, 128, 128};
}

constexpr int legendWidth = 170;         // pixels; fits "interior" and "10.0+" at the font scale below
constexpr int legendMinimumHeight = 260; // the colour bar and the four band keys
constexpr double fontScale = 0.45;
const cv::Scalar legendBackground{40, 40, 40};
const cv::Scalar textColour{235, 235, 235};

std::string formatScale(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", value);
    return text;
}

cv::Mat colourise(const cv::Mat& values, double scaleMax, cv::ColormapTypes map = cv::COLORMAP_INFERNO) {
    cv::Mat scaled(values.size(), CV_8UC1);
    for (int y = 0; y < values.rows; ++y) {
        const auto* in = values.ptr<float>(y);
        auto* out = scaled.ptr<uint8_t>(y);
        for (int x = 0; x < values.cols; ++x) {
            double v = std::isfinite(in[x]) ? in[x] / scaleMax : 1.0;
            out[x] = static_cast<uint8_t>(std::lround(255.0 * std::clamp(v, 0.0, 1.0)));
        }
    }
    cv::Mat coloured;
    cv::applyColorMap(scaled, coloured, map);
    return coloured;
}

} // namespace

cv::Mat renderErrorHeatmap(const cv::Mat& deltaE00, const ErrorBands& bands, double scaleMax) {
    CV_Assert(deltaE00.type() == CV_32FC1 && scaleMax > 0.0);
    cv::Mat heat = colourise(deltaE00, scaleMax);
    for (Band band : allBands) {
        std::vector<std::vector<cv::Point>> contours;
        cv::findContours(bands.mask(band).clone(), contours, cv::RETR_LIST, cv::CHAIN_APPROX_NONE);
        cv::drawContours(heat, contours, -1, bandColour(band), 1, cv::LINE_8);
    }

    const int height = std::max(heat.rows, legendMinimumHeight);
    cv::Mat canvas(height, heat.cols + legendWidth, CV_8UC3, legendBackground);
    heat.copyTo(canvas(cv::Rect(0, 0, heat.cols, heat.rows)));

    // Legend: a vertical colour bar (top = scaleMax and above), then the band outline keys.
    const int left = heat.cols + 12;
    cv::putText(canvas, "dE00 (CIEDE2000)", {left, 18}, cv::FONT_HERSHEY_SIMPLEX, fontScale, textColour, 1,
                cv::LINE_AA);
    const int barTop = 30;
    const int barHeight = 120;
    const int barWidth = 18;
    cv::Mat ramp(barHeight, 1, CV_32FC1);
    for (int i = 0; i < barHeight; ++i)
        ramp.at<float>(i) = static_cast<float>(scaleMax * (1.0 - double(i) / double(barHeight - 1)));
    cv::Mat rampColour;
    cv::resize(colourise(ramp, scaleMax), rampColour, {barWidth, barHeight}, 0, 0, cv::INTER_NEAREST);
    rampColour.copyTo(canvas(cv::Rect(left, barTop, barWidth, barHeight)));
    const double ticks[3] = {scaleMax, 0.5 * scaleMax, 0.0};
    for (int i = 0; i < 3; ++i) {
        int y = barTop + static_cast<int>(std::lround(i * (barHeight - 1) / 2.0));
        cv::line(canvas, {left + barWidth, y}, {left + barWidth + 4, y}, textColour, 1);
        std::string label = formatScale(ticks[i]) + (i == 0 ? "+" : "");
        cv::putText(canvas, label, {left + barWidth + 8, y + 5}, cv::FONT_HERSHEY_SIMPLEX, fontScale, textColour, 1,
                    cv::LINE_AA);
    }
    int keyY = barTop + barHeight + 24;
    for (Band band : allBands) {
        cv::line(canvas, {left, keyY - 4}, {left + 24, keyY - 4}, bandColour(band), 2);
        cv::putText(canvas, std::string(bandName(band)), {left + 32, keyY}, cv::FONT_HERSHEY_SIMPLEX, fontScale,
                    textColour, 1, cv::LINE_AA);
        keyY += 20;
    }
    return canvas;
}

namespace {

void writePng(const std::filesystem::path& path, const cv::Mat& picture) {
    AtomicOutput output(path);
    bool written = false;
    try {
        written = cv::imwrite(output.tempPath().string(), picture);
    } catch (const cv::Exception& e) {
        throwInput(path.string(), "", std::string("cannot write PNG (") + e.err + ")");
    }
    if (!written) throwInput(path.string(), "", "cannot write PNG");
    output.commit();
}

} // namespace

void writeErrorHeatmap(const std::filesystem::path& path, const cv::Mat& deltaE00, const ErrorBands& bands,
                       double scaleMax) {
    writePng(path, renderErrorHeatmap(deltaE00, bands, scaleMax));
}

double automaticScaleMax(const cv::Mat& values, double minimum) {
    cv::Mat asFloat;
    values.convertTo(asFloat, CV_32FC1);
    std::vector<float> finite;
    finite.reserve(asFloat.total());
    for (int y = 0; y < asFloat.rows; ++y) {
        const float* row = asFloat.ptr<float>(y);
        for (int x = 0; x < asFloat.cols; ++x)
            if (std::isfinite(row[x])) finite.push_back(row[x]);
    }
    if (finite.empty()) return std::max(minimum, 1e-12);
    const std::size_t k = std::min(finite.size() - 1, static_cast<std::size_t>(0.99 * double(finite.size())));
    std::nth_element(finite.begin(), finite.begin() + static_cast<std::ptrdiff_t>(k), finite.end());
    const double p99 = std::max(double(finite[k]), minimum);
    const double power = std::pow(10.0, std::floor(std::log10(p99)));
    for (double m : {1.0, 2.0, 5.0, 10.0})
        if (m * power >= p99 * (1.0 - 1e-9)) return m * power;
    return 10.0 * power;
}

namespace {

// A scalar map through `map` on [0, scaleMax] with a legend panel: `title` lines, a colour bar and three ticks (the
// top one marked "+" when larger values saturate below `naturalMax`).
cv::Mat renderScalarHeatmap(const cv::Mat& values, double scaleMax, cv::ColormapTypes map,
                            const std::vector<std::string>& title, double naturalMax) {
    CV_Assert(values.type() == CV_32FC1 && scaleMax > 0.0);
    cv::Mat heat = colourise(values, scaleMax, map);
    const int height = std::max(heat.rows, legendMinimumHeight);
    cv::Mat canvas(height, heat.cols + legendWidth, CV_8UC3, legendBackground);
    heat.copyTo(canvas(cv::Rect(0, 0, heat.cols, heat.rows)));
    const int left = heat.cols + 12;
    for (std::size_t line = 0; line < title.size(); ++line)
        cv::putText(canvas, title[line], {left, 18 + 18 * static_cast<int>(line)}, cv::FONT_HERSHEY_SIMPLEX, fontScale,
                    textColour, 1, cv::LINE_AA);
    const int barTop = 12 + 18 * static_cast<int>(title.size()), barHeight = 120, barWidth = 18;
    cv::Mat ramp(barHeight, 1, CV_32FC1);
    for (int i = 0; i < barHeight; ++i)
        ramp.at<float>(i) = static_cast<float>(scaleMax * (1.0 - double(i) / double(barHeight - 1)));
    cv::Mat rampColour;
    cv::resize(colourise(ramp, scaleMax, map), rampColour, {barWidth, barHeight}, 0, 0, cv::INTER_NEAREST);
    rampColour.copyTo(canvas(cv::Rect(left, barTop, barWidth, barHeight)));
    const double ticks[3] = {scaleMax, 0.5 * scaleMax, 0.0};
    for (int i = 0; i < 3; ++i) {
        int y = barTop + static_cast<int>(std::lround(i * (barHeight - 1) / 2.0));
        cv::line(canvas, {left + barWidth, y}, {left + barWidth + 4, y}, textColour, 1);
        cv::putText(canvas, formatScale(ticks[i]) + (i == 0 && scaleMax < naturalMax ? "+" : ""),
                    {left + barWidth + 8, y + 5}, cv::FONT_HERSHEY_SIMPLEX, fontScale, textColour, 1, cv::LINE_AA);
    }
    return canvas;
}

} // namespace

cv::Mat renderFlipHeatmap(const cv::Mat& flip, double scaleMax) {
    CV_Assert(flip.type() == CV_64FC1 || flip.type() == CV_32FC1);
    cv::Mat values;
    flip.convertTo(values, CV_32FC1);
    return renderScalarHeatmap(values, scaleMax, cv::COLORMAP_MAGMA, {"LDR-FLIP"}, 1.0); // FLIP is at most 1
}

void writeFlipHeatmap(const std::filesystem::path& path, const cv::Mat& flip, double scaleMax) {
    writePng(path, renderFlipHeatmap(flip, scaleMax));
}

cv::Mat renderCvvdpHeatmap(const cv::Mat& visibility, double scaleMax) {
    return renderScalarHeatmap(visibility, scaleMax, cv::COLORMAP_VIRIDIS, {"ColorVideoVDP", "JOD loss"},
                               std::numeric_limits<double>::infinity());
}

void writeCvvdpHeatmap(const std::filesystem::path& path, const cv::Mat& visibility, double scaleMax) {
    writePng(path, renderCvvdpHeatmap(visibility, scaleMax));
}

} // namespace skinlab::metrics
