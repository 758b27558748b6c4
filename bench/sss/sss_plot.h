#pragma once
// Line plot of SSS milliseconds against samples, one panel per view, one line per method (OpenCV drawing, own
// code). Returns PNG bytes.
#include <map>
#include <string>
#include <vector>

namespace skinlab::bench {

struct SssSeries {
    std::string method;
    std::vector<int> samples;
    std::vector<double> milliseconds;
};

// panels: view name → series (one per method). `title` goes above the panels.
std::string plotSssTimings(const std::vector<std::pair<std::string, std::vector<SssSeries>>>& panels,
                           const std::string& title);

} // namespace skinlab::bench
