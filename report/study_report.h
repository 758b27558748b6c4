#pragma once
// `skinlab report`: one self-contained study report (docs/report.md). From a study file (and its stimulus set,
// and image metrics against the set's references) it writes REPORT/index.html with every image copied beside it
// (relative links), REPORT/report.pdf through headless Chromium, and the tables behind the page (scale.json,
// agreement.json/csv, metrics/ when it computed them).
#include "analysis/metrics/cvvdp.h"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace skinlab::report {

struct ReportOptions {
    std::filesystem::path study;   // study.db
    std::filesystem::path stimuli; // stimulus folder; empty = the folder recorded in the study file
    std::filesystem::path metrics; // folder with metrics.json; empty = compute them (when the set has references)
    std::filesystem::path output;  // REPORT/ folder
    int bootstrapSamples = 1000;   // scale intervals and correlation intervals
    std::uint64_t seed = 1;
    int threads = 2;
    // The viewing geometry of the metrics computed here: the display model `display`, else the display of the set's
    // predictions, else standard_fhd; changed by `displayChanges` (pixels per degree, a custom display's
    // resolution, size, distance, photometry); FLIP and ColorVideoVDP use the same.
    std::optional<std::string> display;
    metrics::CvvdpDisplayOverrides displayChanges;
    bool pdf = true;
    std::string chromium = "chromium"; // executable for the PDF
};

struct ReportSummary {
    std::filesystem::path html;
    std::filesystem::path pdf; // empty when no PDF was written
    int observers = 0;
    int excluded = 0;
    bool metrics = false;
};

// Throws InputError for bad input (unreadable study, missing stimulus files, a metrics folder without
// metrics.json); the page is written atomically, after every image.
ReportSummary writeStudyReport(const ReportOptions& options);

} // namespace skinlab::report
