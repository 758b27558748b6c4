#pragma once
// Which renders to compare with which reference: either files named on the command line, or every stimulus of a
// stimulus set (manifest.json, contract 2) against the reference stimulus of its block.
#include "analysis/metrics/cvvdp.h"
#include "formats/stimulus_manifest.h"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace skinlab::metrics {

struct ComparisonJob {
    std::string referenceName; // file stem or stimulus id
    std::filesystem::path referencePath;
    std::string testName; // file stem or stimulus id; names the heat map, so unique within a run
    std::filesystem::path testPath;
    std::string block;                                 // the stimulus block ("" for files)
    nlohmann::json factors = nlohmann::json::object(); // the test stimulus's factor levels ({} for files)
    // Stimulus sets: the presented PNGs (files.png, what observers see) of the reference and the test; the
    // display-referred metrics run on them (docs/metrics.md, "Stimulus sets"). Empty for files, and for a set in
    // which some stimulus lists no PNG (then every score runs on the EXRs).
    std::filesystem::path referencePresented;
    std::filesystem::path testPresented;
};

struct ComparisonPlan {
    std::vector<ComparisonJob> jobs;
    std::vector<std::string> blocksWithoutReference; // stimulus-set blocks that were skipped, in manifest order
    // Stimulus sets: the display model the manifest's predictions used ("predicted": {"display": ...}), when
    // any stimulus has one: the viewing geometry of the set's design.
    std::optional<std::string> display;
    // ... and, when that is "custom", its every parameter ("predicted": {"display_model": ...}).
    std::optional<formats::DisplayModel> displayModel;

    // That display (InputError for a name that is no model): nullopt when no stimulus has a prediction.
    std::optional<CvvdpDisplay> recordedDisplay() const;
};

// One reference file against each test file. Throws InputError when two tests share a file stem.
ComparisonPlan planFileComparisons(const std::filesystem::path& reference,
                                   const std::vector<std::filesystem::path>& tests);

// Every stimulus of the set in `stimulusFolder` against its block's reference. Without `referenceId`, each
// block's stimulus marked "reference": true is its reference (blocks without one are skipped and listed; a
// set with none at all, or a block with two, is an error); with it, that stimulus is the reference of its own
// block only. Checks each EXR's and PNG's sha256 against the manifest. Errors name manifest.json and the JSON path
// ("DIR/manifest.json: stimuli[2].files.exr: missing"); predictions on two different displays are an error
// ("DIR/manifest.json: stimuli[4].predicted.display: ...").
ComparisonPlan planStimulusSetComparisons(const std::filesystem::path& stimulusFolder,
                                          const std::optional<std::string>& referenceId);

} // namespace skinlab::metrics
