#pragma once
// The statistics every benchmark prints (median, percentiles) and its comma-separated options, in one place.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace skinlab::bench {

// The median (the mean of the two middle values for an even count); 0 for no values.
inline double median(std::vector<double> values) {
    if (values.empty()) return 0.0;
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// The p-quantile (p in [0, 1]) interpolated linearly between order statistics; NaN for no values.
inline double percentile(std::vector<double> values, double p) {
    if (values.empty()) return NAN;
    std::sort(values.begin(), values.end());
    const double position = std::clamp(p, 0.0, 1.0) * static_cast<double>(values.size() - 1);
    const auto below = static_cast<std::size_t>(position);
    const auto above = std::min(below + 1, values.size() - 1);
    return values[below] + (position - static_cast<double>(below)) * (values[above] - values[below]);
}

// The nearest-rank p-th percentile (p in percent; the smallest value with at least p % of the values at or below
// it), as latency tails are usually quoted; NaN for no values.
inline double nearestRankPercentile(std::vector<double> values, double p) {
    if (values.empty()) return NAN;
    std::sort(values.begin(), values.end());
    const auto rank = static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(values.size())));
    return values[std::min(values.size() - 1, rank == 0 ? 0 : rank - 1)];
}

// "a,b,c" → {"a", "b", "c"}.
inline std::vector<std::string> splitCommas(const std::string& text) {
    std::vector<std::string> parts;
    std::stringstream stream(text);
    std::string part;
    while (std::getline(stream, part, ',')) parts.push_back(part);
    return parts;
}

} // namespace skinlab::bench
