#include "analysis/scaling/plots.h"

#include "common/error.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace skinlab::analysis::scaling {
namespace {

const cv::Scalar kBlack(0, 0, 0), kGrey(150, 150, 150), kLightGrey(225, 225, 225), kWhite(255, 255, 255);
const cv::Scalar kBlue(180, 90, 30), kOrange(0, 120, 230); // BGR
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

// OpenCV's Hershey fonts draw ASCII only; other bytes become '?'. Long labels are shortened with "..".
std::string label(const std::string& text, size_t maximum) {
    std::string out;
    for (unsigned char c : text) out += (c >= 32 && c < 127) ? static_cast<char>(c) : '?';
    if (out.size() > maximum) out = out.substr(0, maximum - 2) + "..";
    return out;
}

void text(cv::Mat& image, const std::string& value, cv::Point at, double scale, const cv::Scalar& colour,
          int alignment = 0 /* 0 left, 1 centre, 2 right */, int thickness = 1) {
    int baseline = 0;
    const cv::Size size = cv::getTextSize(value, kFont, scale, thickness, &baseline);
    if (alignment == 1) at.x -= size.width / 2;
    if (alignment == 2) at.x -= size.width;
    cv::putText(image, value, at, kFont, scale, colour, thickness, cv::LINE_AA);
}

// Diverging map: 0 → blue (49, 54, 149)ᴿᴳᴮ, 0.5 → white, 1 → red (165, 0, 38)ᴿᴳᴮ (ColorBrewer RdBu end points).
cv::Scalar diverging(double value) {
    const double t = std::clamp(value, 0.0, 1.0);
    auto mix = [](double a, double b, double f) { return a + (b - a) * f; };
    if (t < 0.5) {
        const double f = t / 0.5;
        return cv::Scalar(mix(149, 255, f), mix(54, 255, f), mix(49, 255, f));
    }
    const double f = (t - 0.5) / 0.5;
    return cv::Scalar(mix(255, 38, f), mix(255, 0, f), mix(255, 165, f));
}

std::string format(const char* pattern, double value) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, pattern, value);
    return buffer;
}

} // namespace

cv::Mat plotScores(const BlockAnalysis& block) {
    const int m = static_cast<int>(block.conditions.size());
    const int left = 80, right = 30, top = 60, bottom = 130, slot = 90;
    const int width = std::max(560, left + right + slot * m), height = 480;
    cv::Mat image(height, width, CV_8UC3, kWhite);
    // The axis never depends on the size of a bound: it spans the scores plus a margin (half their range, at least
    // 1.5 JOD); bounds beyond it are clipped and drawn as arrows (the table and scale.json hold their values).
    double scoreLow = 0.0, scoreHigh = 0.0;
    for (int i = 0; i < m; ++i) {
        const double q = block.thurstone.scores[i];
        if (!std::isfinite(q) || (static_cast<size_t>(i) < block.measured.size() && !block.measured[i])) continue;
        scoreLow = std::min(scoreLow, q);
        scoreHigh = std::max(scoreHigh, q);
    }
    const double margin = std::max(1.5, 0.5 * (scoreHigh - scoreLow));
    const double windowLow = scoreLow - margin, windowHigh = scoreHigh + margin;
    auto clipped = [&](double value) { return !std::isfinite(value) || value < windowLow || value > windowHigh; };
    auto clip = [&](double value, double fallback) {
        return std::isfinite(value) ? std::clamp(value, windowLow, windowHigh) : fallback;
    };
    double low = scoreLow, high = scoreHigh;
    bool anyClipped = false, anyFallback = false;
    for (int i = 0; i < m; ++i) {
        if (static_cast<size_t>(i) < block.measured.size() && !block.measured[i]) continue;
        low = std::min(low, clip(block.low[i], windowLow));
        high = std::max(high, clip(block.high[i], windowHigh));
        anyClipped = anyClipped || clipped(block.low[i]) || clipped(block.high[i]);
        anyFallback =
            anyFallback || (static_cast<size_t>(i) < block.intervalFlags.size() && block.intervalFlags[i].fallback);
    }
    const double range = std::max(high - low, 0.5);
    low -= 0.08 * range;
    high += 0.08 * range;
    const int plotBottom = height - bottom, plotTop = top;
    auto y = [&](double value) {
        return static_cast<int>(std::lround(plotBottom - (value - low) / (high - low) * (plotBottom - plotTop)));
    };
    // Grid: the smallest of 0.1, 0.2, 0.5, 1, 2, 5, 10, … JOD that gives at most 12 lines, labelled.
    double step = 0.1;
    for (int k = 0; (high - low) / step > 12.0 && k < 40; ++k) step *= (k % 3 == 1) ? 2.5 : 2.0;
    const double first = std::ceil(low / step);
    for (int g = 0; g <= 13 && (first + g) * step <= high; ++g) {
        const double value = (first + g) * step;
        cv::line(image, {left, y(value)}, {width - right, y(value)}, std::abs(value) < 0.5 * step ? kGrey : kLightGrey,
                 1);
        text(image, format(step < 1.0 ? "%.1f" : "%.0f", value), {left - 8, y(value) + 5}, 0.45, kBlack, 2);
    }
    cv::rectangle(image, {left, plotTop}, {width - right, plotBottom}, kBlack, 1);
    text(image, "JOD", {12, plotTop - 12}, 0.5, kBlack);
    text(image, label(block.name, 36) + " - JOD, 95% interval", {left, 30}, 0.55, kBlack);
    const double columnWidth = static_cast<double>(width - left - right) / m;
    for (int i = 0; i < m; ++i) {
        const int x = static_cast<int>(std::lround(left + (i + 0.5) * columnWidth));
        text(image, label(block.conditions[i], 14), {x, plotBottom + 22 + (i % 2) * 20}, 0.45, kBlack, 1);
        if (static_cast<size_t>(i) < block.measured.size() && !block.measured[i]) {
            text(image, "not measured", {x, plotBottom + 68}, 0.4, kGrey, 1);
            continue;
        }
        const bool fallback = static_cast<size_t>(i) < block.intervalFlags.size() && block.intervalFlags[i].fallback;
        const cv::Scalar colour = fallback ? kOrange : kBlue;
        const int yLow = y(clip(block.low[i], windowLow)), yHigh = y(clip(block.high[i], windowHigh));
        cv::line(image, {x, yLow}, {x, yHigh}, colour, 2, cv::LINE_AA);
        // A bound inside the axis ends in a cap; a clipped one in an arrow head pointing off the axis.
        if (clipped(block.low[i]))
            cv::fillConvexPoly(image, std::vector<cv::Point>{{x - 7, yLow - 10}, {x + 7, yLow - 10}, {x, yLow}}, colour,
                               cv::LINE_AA);
        else cv::line(image, {x - 8, yLow}, {x + 8, yLow}, colour, 2, cv::LINE_AA);
        if (clipped(block.high[i]))
            cv::fillConvexPoly(image, std::vector<cv::Point>{{x - 7, yHigh + 10}, {x + 7, yHigh + 10}, {x, yHigh}},
                               colour, cv::LINE_AA);
        else cv::line(image, {x - 8, yHigh}, {x + 8, yHigh}, colour, 2, cv::LINE_AA);
        if (std::isfinite(block.thurstone.scores[i]))
            cv::circle(image, {x, y(block.thurstone.scores[i])}, 5, kBlack, cv::FILLED, cv::LINE_AA);
        text(image, format("%+.2f", block.thurstone.scores[i]), {x, plotBottom + 68}, 0.4, kGrey, 1);
    }
    int legend = plotBottom + 92;
    if (anyFallback) {
        text(image, "orange: percentile+profile interval (studentized bootstrap degenerate here)", {left, legend}, 0.4,
             kOrange);
        legend += 18;
    }
    if (anyClipped)
        text(image, "arrow: the interval continues beyond the axis (values in the table)", {left, legend}, 0.4, kBlack);
    return image;
}

cv::Mat plotPreferenceMatrix(const BlockAnalysis& block) {
    const int m = static_cast<int>(block.conditions.size());
    const int cell = m <= 12 ? 64 : 40, left = 150, top = 110, legend = 60;
    const int width = left + cell * m + legend + 40, height = std::max(top + cell * m + 50, 300);
    cv::Mat image(height, width, CV_8UC3, kWhite);
    text(image, label(block.name, 40) + " - P(row chosen over column)", {10, 28}, 0.55, kBlack);
    const double fontScale = cell >= 64 ? 0.42 : 0.32;
    for (int i = 0; i < m; ++i) {
        text(image, label(block.conditions[i], 18), {left - 8, top + i * cell + cell / 2 + 5}, 0.42, kBlack, 2);
        // Column labels: staggered in two rows above the matrix.
        text(image, label(block.conditions[i], cell >= 64 ? 9 : 6),
             {left + i * cell + cell / 2, top - 14 - (i % 2) * 22}, 0.4, kBlack, 1);
        for (int j = 0; j < m; ++j) {
            const cv::Rect rect(left + j * cell, top + i * cell, cell, cell);
            const double wins = block.counts(i, j), total = block.counts(i, j) + block.counts(j, i);
            if (i == j || total <= 0) {
                cv::rectangle(image, rect, i == j ? kWhite : kLightGrey, cv::FILLED);
            } else {
                const double probability = wins / total;
                cv::rectangle(image, rect, diverging(probability), cv::FILLED);
                const cv::Scalar ink = std::abs(probability - 0.5) > 0.3 ? kWhite : kBlack;
                text(image, format("%.0f%%", 100.0 * probability), {rect.x + cell / 2, rect.y + cell / 2}, fontScale,
                     ink, 1);
                text(image, format("n=%.0f", total), {rect.x + cell / 2, rect.y + cell / 2 + 16}, fontScale * 0.8, ink,
                     1);
            }
            cv::rectangle(image, rect, kGrey, 1);
        }
    }
    // Colour bar 0 % .. 100 %.
    const int barX = left + cell * m + 20, barTop = top, barHeight = cell * m;
    for (int r = 0; r < barHeight; ++r)
        cv::line(image, {barX, barTop + r}, {barX + 16, barTop + r},
                 diverging(1.0 - static_cast<double>(r) / barHeight));
    cv::rectangle(image, {barX, barTop}, {barX + 16, barTop + barHeight}, kGrey, 1);
    text(image, "100%", {barX, barTop - 6}, 0.38, kBlack);
    text(image, "0%", {barX, barTop + barHeight + 16}, 0.38, kBlack);
    return image;
}

std::string encodePng(const cv::Mat& image) {
    std::vector<unsigned char> bytes;
    if (!cv::imencode(".png", image, bytes)) throw RuntimeError("cv::imencode: cannot encode a PNG image");
    return std::string(bytes.begin(), bytes.end());
}

} // namespace skinlab::analysis::scaling
