#pragma once
// Inline SVG plots of the study report: a JOD scale with intervals and metric-versus-JOD scatter plots. Axis
// ranges come from the point estimates, never from the size of an interval: bounds beyond the range are clipped
// and marked with an arrow, so any input draws in bounded time.
#include <string>
#include <vector>

namespace skinlab::report {

struct IntervalPoint {
    std::string label;
    double value = 0.0, low = 0.0, high = 0.0;
};

// One row per point, in the given order: a dot at `value` and a bar from `low` to `high` (JOD); the label left of
// the axis, in a margin as wide as the longest label needs (kLabelCharacterPx a character).
inline constexpr double kLabelCharacterPx = 7.0;
std::string scaleSvg(const std::vector<IntervalPoint>& points);

struct ScatterPoint {
    std::string label;
    double x = 0.0;                        // metric value
    double y = 0.0, low = 0.0, high = 0.0; // JOD and its interval
};

struct ScatterOptions {
    std::string yLabel = "JOD";
    // Both axes share one range and the line y = x is drawn (measured against predicted JOD).
    bool identity = false;
};

std::string scatterSvg(const std::vector<ScatterPoint>& points, const std::string& xLabel,
                       const ScatterOptions& options = {});

// A correlation's interval for the page: "[0.12, 0.95]", or why there is none: "(no interval with 3 conditions: Fisher
// z needs 4)" (its variance is 1/(n − 3)), or "(no interval)" when the correlation itself is undefined.
std::string correlationIntervalText(double low, double high, int conditions);

// A number for the page: `digits` after the point, "−" for minus, "—" for a non-finite value.
std::string formatNumber(double value, int digits);
// An interval on the page: "[a, b]", "at least a" or "at most b" where one end is unbounded (infinite or not a
// number), "none" where both are.
std::string intervalText(double low, double high, int digits);

} // namespace skinlab::report
