#pragma once
// Visibility against viewing distance (`skinlab stimuli visibility SET`, docs/stimuli.md "Visibility against viewing
// distance"): every stimulus of a block with a reference is compared with it by ColorVideoVDP on the presented PNGs
// at a range of pixels per degree (the set's display model otherwise), so that a researcher sees at what viewing
// distance a comparison stops being visible. Written into the set folder, atomically:
//   visibility.json  format "skinlab-visibility", version 1: display, pixels per degree, distances, one row per
//                    stimulus with its JOD at each ppd and the ppd/distance where it reaches 9 JOD;
//   visibility.csv   the same rows (block, reference, stimulus, jod_ppd_20, ..., one_jod_ppd, one_jod_distance_m);
//   visibility.svg   one plot per block: JOD against pixels per degree (log scale), a line per condition.
// The contact sheet (contact_sheet.h) shows the table and the plot when visibility.json matches the set's PNGs.
#include "analysis/metrics/cvvdp.h"
#include "stimuli/manifest.h"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace skinlab::stimuli {

// The default range: from a phone at arm's length to a 4K monitor seen from afar.
inline const std::vector<double> kVisibilityPixelsPerDegree = {20.0, 30.0, 40.0, 60.0, 80.0, 120.0};

// A comparison is called visible while it lies at least 1 JOD below the reference's 10: one JOD is the difference
// that 75 % of observers see in a 2AFC trial.
inline constexpr double kVisibleBelowJod = 9.0;

struct VisibilityOptions {
    std::string display; // empty: the set's predictions', else standard_fhd
    std::vector<double> pixelsPerDegree = kVisibilityPixelsPerDegree; // ascending, each > 0
    int jobs = 2;                                                     // threads (ColorVideoVDP is thread-safe)
};

struct VisibilityRow {
    std::string block;
    std::string reference;   // stimulus id
    std::string stimulus;    // stimulus id
    std::vector<double> jod; // per pixels per degree
    // Where the row's JOD reaches kVisibleBelowJod (linear in log ppd between the two neighbouring ppds): nullopt
    // when it never does in the range; `visibleEverywhere` / `invisibleEverywhere` tell the cases apart.
    std::optional<double> limitPixelsPerDegree;
    bool visibleEverywhere = false;   // below 9 JOD at every ppd of the range
    bool invisibleEverywhere = false; // at or above 9 JOD at every ppd of the range
};

struct VisibilityTable {
    metrics::CvvdpDisplay display; // photometry; its ppd replaced by each of `pixelsPerDegree`
    std::string displaySource;     // "the set's predictions", "--display", "default"
    std::vector<double> pixelsPerDegree;
    std::vector<double> distanceMetres; // viewing distance on the display model at each ppd; empty without geometry
    std::vector<VisibilityRow> rows;    // blocks in manifest order, stimuli in manifest order
    nlohmann::json pngSha256 = nlohmann::json::object(); // stimulus id → sha256 of the PNG compared
    double seconds = 0.0;                                // wall time of the computation
};

// Viewing distance in metres at which `display` (with resolution and diagonal) has `pixelsPerDegree` at the centre;
// nullopt when the model has no geometry.
std::optional<double> viewingDistanceAt(const metrics::CvvdpDisplay& display, double pixelsPerDegree);

// Computes the table for the set in `dir` (whose manifest must be complete). Throws InputError for a bad option
// ("--ppd: ...", "--display: ..."), or for a set without a reference in any block.
VisibilityTable computeVisibility(const std::filesystem::path& dir, const Manifest& manifest,
                                  const VisibilityOptions& options);

nlohmann::json visibilityJson(const VisibilityTable& table);
std::string visibilityCsv(const VisibilityTable& table);
std::string visibilitySvg(const VisibilityTable& table);

// Writes visibility.svg, visibility.csv and then visibility.json (last: a complete visibility.json means a complete
// run) into `dir`, atomically.
void writeVisibility(const std::filesystem::path& dir, const VisibilityTable& table);

// DIR/visibility.json when it exists and was computed on the PNGs the manifest lists now (nullopt otherwise).
std::optional<nlohmann::json> currentVisibility(const std::filesystem::path& dir, const Manifest& manifest);

} // namespace skinlab::stimuli
