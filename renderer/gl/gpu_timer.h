#pragma once
// Per-pass timings: a GL_TIME_ELAPSED query around each pass, cross-checked with wall-clock time measured
// between glFinish() calls.
//
// Why both: llvmpipe's first GL_TIME_ELAPSED query of a context can return garbage (hundreds of seconds; see
// design.md), so the constructor issues one throw-away query; and a GPU time larger than the wall-clock time
// of the same glFinish-bracketed pass is impossible, so such a value is replaced by the wall-clock time and
// the pass is listed in "gpu_from_wall" (absent when every GPU value is the timer's own). The glFinish brackets serialise the frame; that costs a little
// throughput but makes every figure attributable to one pass.
#include "renderer/gl/gl_resources.h"

#include <chrono>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace skinlab::renderer::gl {

// Milliseconds to the microsecond (3 decimals): timings are written as 0.02, not 1.9999999999999998e-05.
double roundMs(double milliseconds);
// A copy of a timings record with every floating-point value rounded by roundMs (integers and text as they are).
nlohmann::json roundTimings(nlohmann::json timings);

class PassTimer {
public:
    PassTimer(); // issues and discards the context's first timer query

    void begin(const std::string& pass);
    void end();
    // Clears the recorded passes (a new frame). A pass left open by a render that threw is closed and dropped,
    // so that one failed render does not break the next one on the same context.
    void reset();

    // {"passes": {name: gpu ms}, "passes_wall": {name: wall ms}, "gpu_total": ms, "wall_total": ms[,
    //  "gpu_from_wall": [passes whose GPU time is their wall-clock time]]}, every figure to 1 µs (roundMs).
    nlohmann::json json() const;

    struct Record {
        std::string pass;
        double gpuMs = 0;
        double wallMs = 0;
        bool replaced = false;
    };
    const std::vector<Record>& records() const { return records_; }

private:
    Query query_;
    std::chrono::steady_clock::time_point wallStart_;
    std::string current_;
    std::vector<Record> records_;
};

} // namespace skinlab::renderer::gl
