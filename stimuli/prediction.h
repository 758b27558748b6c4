#pragma once
// Predicted visibility of a built set: every stimulus of a block that has a reference render is compared with it by
// ColorVideoVDP (analysis/metrics/cvvdp.h) on the PNGs a participant would see, on a named or custom display, and the
// JOD (10 = indistinguishable from the reference) is recorded in its manifest entry:
//   "predicted": {"metric": "ColorVideoVDP v0.5.6", "display": "standard_fhd", "reference": ID, "jod": 9.62}
// A block whose conditions all lie within `invisibleBelow` JOD of each other is reported: a 2AFC study of it would
// measure (almost) nothing.
#include "analysis/metrics/cvvdp.h"
#include "stimuli/manifest.h"

#include <filesystem>
#include <string>
#include <vector>

namespace skinlab::stimuli {

struct PredictionOptions {
    // A model of analysis/metrics/cvvdp/display_models.json, or a custom display (a model changed by --display-*,
    // recorded in full in the manifest: predicted.display_model).
    metrics::CvvdpDisplay display = metrics::cvvdpDisplay("standard_fhd");
    double invisibleBelow = 0.25; // JOD: the spread under which a block is called invisible
};

struct BlockPrediction {
    std::string block;
    std::string reference;  // stimulus id
    double lowest = 0.0;    // JOD of the condition predicted most different from the reference
    double highest = 0.0;   // JOD of the condition predicted closest to it
    int conditions = 0;     // stimuli compared
    bool invisible = false; // highest − lowest < invisibleBelow
};

struct PredictionSummary {
    std::vector<BlockPrediction> blocks;
    int predicted = 0; // stimuli given a prediction in this run (others were already up to date)
};

// Adds or refreshes "predicted" on every non-reference stimulus of a block with a reference in `manifest` (which
// must be complete), reading the PNGs under `dir`. A prediction is kept when its display and reference (by
// sha256 of both PNGs) are unchanged.
PredictionSummary predictStimuli(const std::filesystem::path& dir, Manifest& manifest,
                                 const PredictionOptions& options);

// One line per block for the end of a build: "block B: predicted JOD 9.54–9.71 against REF (spread 0.17)", and a
// warning line for an invisible block.
std::vector<std::string> predictionLines(const PredictionSummary& summary, const PredictionOptions& options);

} // namespace skinlab::stimuli
