#include "report/report_plots.h"

#include "common/html.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace skinlab::report {
namespace {

std::string px(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f", value);
    return text;
}

struct Range {
    double low = 0.0, high = 1.0;
    double map(double v, double from, double to) const { return from + (v - low) / (high - low) * (to - from); }
};

// Range of the finite values, padded; at least `minimumSpan` wide.
Range rangeOf(const std::vector<double>& values, double pad, double minimumSpan) {
    Range range{INFINITY, -INFINITY};
    for (double v : values)
        if (std::isfinite(v)) {
            range.low = std::min(range.low, v);
            range.high = std::max(range.high, v);
        }
    if (!std::isfinite(range.low)) return {0.0, 1.0};
    double span = std::max(range.high - range.low, minimumSpan);
    double centre = 0.5 * (range.low + range.high);
    return {centre - 0.5 * span - pad * span, centre + 0.5 * span + pad * span};
}

// Up to ~6 round tick values inside the range.
std::vector<double> ticks(const Range& range) {
    double span = range.high - range.low;
    double step = std::pow(10.0, std::floor(std::log10(span / 5.0)));
    for (double factor : {1.0, 2.0, 5.0, 10.0})
        if (span / (step * factor) <= 6.0) {
            step *= factor;
            break;
        }
    std::vector<double> out;
    for (double t = std::ceil(range.low / step) * step; t <= range.high + 1e-12 && out.size() < 12; t += step)
        out.push_back(std::fabs(t) < 1e-12 * step ? 0.0 : t);
    return out;
}

std::string tickLabel(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    std::string s = text;
    if (!s.empty() && s[0] == '-') s = "\u2212" + s.substr(1);
    return s;
}

// Characters of a UTF-8 label (continuation bytes do not count).
std::size_t labelCharacters(const std::string& label) {
    return static_cast<std::size_t>(std::count_if(
        label.begin(), label.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}

} // namespace

std::string formatNumber(double value, int digits) {
    if (!std::isfinite(value)) return "\u2014";
    char text[48];
    std::snprintf(text, sizeof text, "%.*f", digits, value);
    std::string s = text;
    if (s.rfind("-", 0) == 0) {
        // "-0.00" is zero.
        bool zero = s.find_first_not_of("-0.") == std::string::npos;
        s = zero ? s.substr(1) : "\u2212" + s.substr(1);
    }
    return s;
}

std::string intervalText(double low, double high, int digits) {
    if (std::isfinite(low) && std::isfinite(high))
        return "[" + formatNumber(low, digits) + ", " + formatNumber(high, digits) + "]";
    if (std::isfinite(low)) return "at least " + formatNumber(low, digits);
    if (std::isfinite(high)) return "at most " + formatNumber(high, digits);
    return "none";
}

std::string correlationIntervalText(double low, double high, int conditions) {
    if (std::isfinite(low) && std::isfinite(high))
        return "[" + formatNumber(low, 2) + ", " + formatNumber(high, 2) + "]";
    if (conditions < 4) return "(no interval with " + std::to_string(conditions) + " conditions: Fisher z needs 4)";
    return "(no interval)";
}

std::string scaleSvg(const std::vector<IntervalPoint>& points) {
    // The labels stand right-aligned left of the axis: the margin holds the longest one (12 px sans-serif, at most
    // ~7 px a character), the axis keeps its 470 px.
    std::size_t longest = 0;
    for (const auto& p : points) longest = std::max(longest, labelCharacters(p.label));
    const double left = std::max(150.0, kLabelCharacterPx * static_cast<double>(longest) + 16.0);
    const double right = left + 470.0, rowHeight = 26.0, top = 20.0, width = right + 20.0;
    const double height = top + rowHeight * static_cast<double>(points.size()) + 36.0;
    std::vector<double> values;
    for (const auto& p : points) values.push_back(p.value);
    // The axis spans the estimates with 1.5 JOD to spare on each side; longer bars are clipped (arrow).
    Range range = rangeOf(values, 0.0, 1.0);
    range.low -= 1.5;
    range.high += 1.5;
    std::string svg = "<svg class=\"plot\" xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 " + px(width) + " " +
                      px(height) + "\" width=\"" + px(width) + "\" height=\"" + px(height) + "\" role=\"img\">";
    const double axisY = top + rowHeight * static_cast<double>(points.size()) + 4.0;
    for (double t : ticks(range)) {
        double x = range.map(t, left, right);
        svg += "<line x1=\"" + px(x) + "\" y1=\"" + px(top - 6) + "\" x2=\"" + px(x) + "\" y2=\"" + px(axisY) +
               "\" class=\"grid\"/><text x=\"" + px(x) + "\" y=\"" + px(axisY + 16) + "\" class=\"tick\">" +
               tickLabel(t) + "</text>";
    }
    svg += "<text x=\"" + px(0.5 * (left + right)) + "\" y=\"" + px(axisY + 32) + "\" class=\"axis\">JOD</text>";
    for (std::size_t i = 0; i < points.size(); ++i) {
        const IntervalPoint& p = points[i];
        double y = top + rowHeight * (static_cast<double>(i) + 0.5);
        svg += "<text x=\"" + px(left - 8) + "\" y=\"" + px(y + 4) + "\" class=\"label\">" + escapeHtml(p.label) +
               "</text>";
        if (!std::isfinite(p.value)) continue;
        double low = std::isfinite(p.low) ? p.low : range.low - 1.0;
        double high = std::isfinite(p.high) ? p.high : range.high + 1.0;
        bool clippedLow = low<range.low, clippedHigh = high> range.high;
        double x0 = range.map(std::max(low, range.low), left, right);
        double x1 = range.map(std::min(high, range.high), left, right);
        double xv = range.map(p.value, left, right);
        svg += "<line x1=\"" + px(x0) + "\" y1=\"" + px(y) + "\" x2=\"" + px(x1) + "\" y2=\"" + px(y) +
               "\" class=\"bar\"/>";
        if (clippedLow)
            svg += "<path d=\"M" + px(x0) + " " + px(y) +
                   " l8 -5 v10 z\" class=\"clip\"><title>interval continues to " + formatNumber(p.low, 2) +
                   "</title></path>";
        if (clippedHigh)
            svg += "<path d=\"M" + px(x1) + " " + px(y) +
                   " l-8 -5 v10 z\" class=\"clip\"><title>interval continues to " + formatNumber(p.high, 2) +
                   "</title></path>";
        svg += "<circle cx=\"" + px(xv) + "\" cy=\"" + px(y) + "\" r=\"4.5\" class=\"dot\"/>";
    }
    return svg + "</svg>";
}

namespace {

// A point's label: anchored beside the point, on the side with room.
struct PointLabel {
    double x = 0.0, y = 0.0;
    bool leftSide = false;
    std::string text;
};

// Moves labels whose boxes would overlap an earlier one up or down in steps of a line (11 px), the nearest free
// place first, within [top, bottom] (boxes: 10 px high, 6 px a character at the labels' 10 px font).
void separateLabels(std::vector<PointLabel>& labels, double top, double bottom) {
    auto extent = [](const PointLabel& l, double& from, double& to) {
        std::size_t characters = 0;
        for (unsigned char c : l.text) characters += (c & 0xC0) != 0x80; // UTF-8 code points
        const double width = 6.0 * double(characters);
        from = l.leftSide ? l.x - width : l.x;
        to = l.leftSide ? l.x : l.x + width;
    };
    for (std::size_t i = 0; i < labels.size(); ++i) {
        const double original = labels[i].y;
        auto overlaps = [&](double y) {
            double from = 0.0, to = 0.0;
            extent(labels[i], from, to);
            for (std::size_t j = 0; j < i; ++j) {
                double otherFrom = 0.0, otherTo = 0.0;
                extent(labels[j], otherFrom, otherTo);
                if (to > otherFrom && otherTo > from && std::abs(y - labels[j].y) < 10.0) return true;
            }
            return false;
        };
        for (int step = 0; step <= 16; ++step) {
            const double y = original + (step % 2 == 1 ? 1.0 : -1.0) * 11.0 * double((step + 1) / 2);
            if (y >= top && y <= bottom && !overlaps(y)) {
                labels[i].y = y;
                break;
            }
        }
    }
}

} // namespace

std::string scatterSvg(const std::vector<ScatterPoint>& points, const std::string& xLabel,
                       const ScatterOptions& options) {
    const double left = 52.0, right = 330.0, top = 14.0, bottom = 212.0;
    std::vector<double> xs, ys;
    for (const auto& p : points) {
        xs.push_back(p.x);
        ys.push_back(p.y);
    }
    Range rx = rangeOf(xs, 0.08, 1e-6);
    // The axis holds the estimates and their intervals where those stay within 1.5 JOD of them; longer bars are
    // clipped and end in a red arrow (with the value in its tooltip).
    for (const auto& p : points) {
        if (std::isfinite(p.low)) ys.push_back(std::max(p.low, p.y - 1.5));
        if (std::isfinite(p.high)) ys.push_back(std::min(p.high, p.y + 1.5));
    }
    Range ry = rangeOf(ys, 0.05, 1.0);
    if (options.identity) { // one range for both axes, so y = x is the diagonal
        rx.low = ry.low = std::min(rx.low, ry.low);
        rx.high = ry.high = std::max(rx.high, ry.high);
    }
    std::string svg = "<svg class=\"plot scatter\" xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 350 256\" "
                      "width=\"350\" height=\"256\" role=\"img\">";
    for (double t : ticks(rx)) {
        double x = rx.map(t, left, right);
        svg += "<line x1=\"" + px(x) + "\" y1=\"" + px(top) + "\" x2=\"" + px(x) + "\" y2=\"" + px(bottom) +
               "\" class=\"grid\"/><text x=\"" + px(x) + "\" y=\"" + px(bottom + 14) + "\" class=\"tick\">" +
               tickLabel(t) + "</text>";
    }
    for (double t : ticks(ry)) {
        double y = ry.map(t, bottom, top);
        svg += "<line x1=\"" + px(left) + "\" y1=\"" + px(y) + "\" x2=\"" + px(right) + "\" y2=\"" + px(y) +
               "\" class=\"grid\"/><text x=\"" + px(left - 6) + "\" y=\"" + px(y + 4) + "\" class=\"tick ytick\">" +
               tickLabel(t) + "</text>";
    }
    svg += "<text x=\"" + px(0.5 * (left + right)) + "\" y=\"250\" class=\"axis\">" + escapeHtml(xLabel) + "</text>";
    svg += "<text x=\"12\" y=\"" + px(0.5 * (top + bottom)) + "\" class=\"axis\" transform=\"rotate(-90 12 " +
           px(0.5 * (top + bottom)) + ")\">" + escapeHtml(options.yLabel) + "</text>";
    if (options.identity)
        svg += "<line x1=\"" + px(left) + "\" y1=\"" + px(bottom) + "\" x2=\"" + px(right) + "\" y2=\"" + px(top) +
               "\" class=\"identity\"><title>measured = predicted</title></line>";
    std::vector<PointLabel> labels;
    for (const auto& p : points) {
        if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
        double x = rx.map(p.x, left, right);
        const bool clippedLow = !std::isfinite(p.low) || p.low < ry.low;
        const bool clippedHigh = !std::isfinite(p.high) || p.high > ry.high;
        double lowValue = clippedLow ? ry.low : p.low;
        double highValue = clippedHigh ? ry.high : p.high;
        svg += "<line x1=\"" + px(x) + "\" y1=\"" + px(ry.map(lowValue, bottom, top)) + "\" x2=\"" + px(x) +
               "\" y2=\"" + px(ry.map(highValue, bottom, top)) + "\" class=\"bar\"/>";
        if (clippedLow)
            svg += "<path d=\"M" + px(x) + " " + px(bottom + 2) +
                   " l-5 -8 h10 z\" class=\"clip\"><title>interval "
                   "continues to " +
                   formatNumber(p.low, 2) + " JOD</title></path>";
        if (clippedHigh)
            svg += "<path d=\"M" + px(x) + " " + px(top - 2) +
                   " l-5 8 h10 z\" class=\"clip\"><title>interval "
                   "continues to " +
                   formatNumber(p.high, 2) + " JOD</title></path>";
        double y = ry.map(p.y, bottom, top);
        // Labels on the side with room: left of points in the right part of the plot, so none runs off the figure.
        const bool leftSide = x > left + 0.6 * (right - left);
        svg += "<circle cx=\"" + px(x) + "\" cy=\"" + px(y) + "\" r=\"4\" class=\"dot\"><title>" + escapeHtml(p.label) +
               "</title></circle>";
        labels.push_back({leftSide ? x - 6 : x + 6, std::max(y - 6, top + 8), leftSide, p.label});
    }
    separateLabels(labels, top + 8, bottom);
    for (const PointLabel& l : labels)
        svg += "<text x=\"" + px(l.x) + "\" y=\"" + px(l.y) + "\" class=\"point\"" +
               (l.leftSide ? " text-anchor=\"end\"" : "") + ">" + escapeHtml(l.text) + "</text>";
    return svg + "</svg>";
}

} // namespace skinlab::report
