#pragma once
// `skinlab stimuli calibrate`: levels of a numeric scene parameter whose predicted visible difference from a
// reference is a chosen number of JOD (ColorVideoVDP, analysis/metrics/cvvdp.h), found by bisection on the
// prediction. The search itself (searchLevels) takes the prediction as a function, so that it is tested without
// rendering; calibrateLevels renders each probe of one stimulus of a set spec with the set's fixed parameters.
#include "analysis/metrics/cvvdp.h"

#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace skinlab::stimuli {

// The interval searched and when a probe is close enough.
struct LevelSearch {
    double lo = 0.0;
    double hi = 1.0;
    double tolerance = 0.05; // JOD: a probe whose difference is within this of the target ends the search
    int maxProbes = 24;      // per target, after the two ends
    bool integral = false;   // the parameter takes whole numbers only (probes are rounded)
};

// One target: the value found and what was achieved there.
struct CalibratedLevel {
    double targetJod = 0.0;                                  // wanted difference, JOD (10 − predicted JOD)
    bool reached = false;                                    // a value within the tolerance was found
    double value = std::numeric_limits<double>::quiet_NaN(); // the value whose difference is closest to the target
    double achievedJod = std::numeric_limits<double>::quiet_NaN(); // its difference (10 − predicted JOD)
    int renders = 0;  // predictions made for this target (probes shared with earlier targets are not counted)
    std::string note; // why the target was not reached ("" when reached)
};

struct LevelSearchResult {
    double differenceAtLo = 0.0;         // 10 − predicted JOD at lo
    double differenceAtHi = 0.0;         // at hi
    std::vector<CalibratedLevel> levels; // in the order of the targets
    int predictions = 0;                 // distinct values predicted (the two ends included)
    std::vector<std::string> warnings;   // probes that break monotonicity, a parameter without effect
};

// For each target T (JOD, > 0), a value v in [lo, hi] with |10 − predictedJod(v) − T| ≤ tolerance, by bisection
// between the two ends, assuming the difference 10 − predictedJod(v) is monotone over [lo, hi] (increasing or
// decreasing). A target outside the differences at the two ends is reported unreachable (note names both ends);
// a probe whose difference leaves its bracket is reported as a warning. Every value is predicted once (targets
// share probes). Throws InputError naming --range, --tolerance or --target-jod for bad arguments.
LevelSearchResult searchLevels(const std::function<double(double)>& predictedJod, const std::vector<double>& targets,
                               const LevelSearch& search);

// A value as TOML text: the shortest text that reads back as the same double, a float ("2.0", "0.8125") unless
// `integral`.
std::string levelText(double value, bool integral);

struct CalibrateOptions {
    std::filesystem::path spec;
    std::vector<std::string> specOverrides; // --set on the set spec
    std::filesystem::path assetsDir;        // empty: $SKINLAB_ASSETS
    std::string factor;                     // the scene key to calibrate (factor name or dotted key)
    std::vector<double> targets;            // JOD
    std::optional<double> referenceLevel;   // reference = the base stimulus at this value; else the [[reference]]
    std::optional<std::pair<double, double>> range; // default: the smallest and largest level of the spec's factor
    double tolerance = 0.05;
    int maxProbes = 24;
    metrics::CvvdpDisplay display = metrics::cvvdpDisplay("standard_fhd"); // ColorVideoVDP's (named or custom)
    std::string stimulus; // id of the stimulus whose parameter varies; empty: the first non-reference
};

struct CalibrationReport {
    std::string set;
    std::string factor;    // the factor name as given
    std::string key;       // its scene key
    std::string stimulus;  // id of the varied stimulus
    std::string reference; // id of the [[reference]] stimulus, or "KEY=V" of the reference level
    std::string display;   // one-line description of the display
    bool integral = false; // the key takes whole numbers
    LevelSearch search;
    LevelSearchResult result;
    int renders = 0; // all renders, the reference included
    double wallSeconds = 0.0;
};

// Plans the set (every spec check of `stimuli build`), renders the reference and the probes into a temporary
// folder and searches. Throws InputError (one line naming the option, key or spec) for bad input.
CalibrationReport calibrateLevels(const CalibrateOptions& options);

// The levels as a [[factor]] table to paste into a spec (reached targets only, in increasing value), preceded by
// comments stating how they were found.
std::string levelsToml(const CalibrationReport& report);

} // namespace skinlab::stimuli
