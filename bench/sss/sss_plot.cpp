#include "sss_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace skinlab::bench {

namespace {
const cv::Scalar kColours[] = {cv::Scalar(40, 40, 200), cv::Scalar(40, 150, 40), cv::Scalar(200, 90, 30),
                               cv::Scalar(150, 40, 150)}; // BGR

std::string label(double v) {
    char text[32];
    std::snprintf(text, sizeof text, v >= 100 ? "%.0f" : v >= 10 ? "%.0f" : "%.1f", v);
    return text;
}

// A "nice" upper bound for an axis: 1, 2, 5 × 10^k at or above v.
double niceCeiling(double v) {
    const double p = std::pow(10.0, std::floor(std::log10(std::max(v, 1e-9))));
    for (double m : {1.0, 2.0, 5.0, 10.0})
        if (m * p >= v) return m * p;
    return 10.0 * p;
}
} // namespace

std::string plotSssTimings(const std::vector<std::pair<std::string, std::vector<SssSeries>>>& panels,
                           const std::string& title) {
    const int panelWidth = 420, panelHeight = 340, left = 60, right = 15, top = 60, bottom = 50;
    const int width = left + static_cast<int>(panels.size()) * (panelWidth + right);
    const int height = top + panelHeight + bottom + 30;
    cv::Mat image(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::putText(image, title, cv::Point(left, 25), cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    int maxSamples = 1;
    double maxMs = 0.0;
    for (const auto& [view, series] : panels)
        for (const auto& s : series) {
            for (int n : s.samples) maxSamples = std::max(maxSamples, n);
            for (double ms : s.milliseconds) maxMs = std::max(maxMs, ms);
        }
    const double yMax = niceCeiling(maxMs);
    const double xMax = maxSamples;
    for (size_t p = 0; p < panels.size(); ++p) {
        const int x0 = left + static_cast<int>(p) * (panelWidth + right);
        const int y0 = top + panelHeight; // origin (bottom-left)
        auto toPixel = [&](double samples, double ms) {
            return cv::Point(x0 + static_cast<int>(std::lround(samples / xMax * panelWidth)),
                             y0 - static_cast<int>(std::lround(ms / yMax * panelHeight)));
        };
        cv::rectangle(image, cv::Point(x0, top), cv::Point(x0 + panelWidth, y0), cv::Scalar(0, 0, 0), 1);
        for (int t = 0; t <= 5; ++t) {
            const double ms = yMax * t / 5.0;
            const cv::Point a = toPixel(0, ms);
            cv::line(image, a, toPixel(xMax, ms), cv::Scalar(225, 225, 225), 1);
            if (p == 0)
                cv::putText(image, label(ms), cv::Point(5, a.y + 5), cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0),
                            1, cv::LINE_AA);
        }
        for (int n = 0; n <= maxSamples; n += maxSamples > 50 ? 20 : 10) {
            const cv::Point a = toPixel(n, 0);
            cv::line(image, a, cv::Point(a.x, a.y + 4), cv::Scalar(0, 0, 0), 1);
            cv::putText(image, std::to_string(n), cv::Point(a.x - 8, a.y + 18), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                        cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
        }
        cv::putText(image, "view: " + panels[p].first, cv::Point(x0 + 8, top + 18), cv::FONT_HERSHEY_SIMPLEX, 0.5,
                    cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
        cv::putText(image, "samples per pass", cv::Point(x0 + panelWidth / 2 - 60, y0 + 38), cv::FONT_HERSHEY_SIMPLEX,
                    0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
        const auto& series = panels[p].second;
        for (size_t s = 0; s < series.size(); ++s) {
            const cv::Scalar colour = kColours[s % 4];
            for (size_t i = 0; i < series[s].samples.size(); ++i) {
                const cv::Point pt = toPixel(series[s].samples[i], series[s].milliseconds[i]);
                cv::circle(image, pt, 3, colour, cv::FILLED, cv::LINE_AA);
                if (i > 0)
                    cv::line(image, toPixel(series[s].samples[i - 1], series[s].milliseconds[i - 1]), pt, colour, 2,
                             cv::LINE_AA);
            }
            cv::line(image, cv::Point(x0 + 10, top + 38 + 18 * static_cast<int>(s)),
                     cv::Point(x0 + 35, top + 38 + 18 * static_cast<int>(s)), colour, 2, cv::LINE_AA);
            cv::putText(image, series[s].method, cv::Point(x0 + 42, top + 43 + 18 * static_cast<int>(s)),
                        cv::FONT_HERSHEY_SIMPLEX, 0.45, colour, 1, cv::LINE_AA);
        }
    }
    cv::putText(image, "SSS ms", cv::Point(5, top - 10), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1,
                cv::LINE_AA);
    std::vector<unsigned char> png;
    cv::imencode(".png", image, png);
    return std::string(png.begin(), png.end());
}

} // namespace skinlab::bench
