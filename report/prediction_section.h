#pragma once
// The study report's "Predicted and measured" section: per block, the JOD a model of vision predicted for each
// condition (the manifest's "predicted" entries, ColorVideoVDP against the block's reference, written by
// `skinlab stimuli build`) against the JOD the observers' answers gave, both as differences to the same anchor (the
// condition predicted closest to the reference), with the identity line, the measured intervals, and the agreement:
// least-squares slope and RMSE with bootstrap intervals, Spearman's ρ with its exact p and interval.
#include "analysis/scaling/scale_analysis.h"
#include "experiments/study_definition.h"
#include "formats/stimulus_manifest.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace skinlab::report {

struct PredictionAgreement {
    std::string block;
    std::string anchor;                  // the condition predicted closest to the reference: predicted Δ = 0
    std::vector<std::string> conditions; // with a prediction and a measurement
    std::vector<double> predicted;       // JOD difference to the anchor
    // The measured score, shifted so that its mean over these conditions is the predictions' mean: no condition
    // (the anchor included) is a fixed point, each keeps its own interval.
    std::vector<double> measured;
    std::vector<double> low, high; // the measured score's interval, shifted alike (±∞: an open end)
    int observers = 0;
    // Least squares of measured on predicted with an intercept (the measured scale's zero is arbitrary); RMSE of
    // measured − predicted about their mean difference (n − 1 degrees of freedom). Intervals: bootstrap over
    // observers (each resample re-fits the scale; ± t·sd with the small-sample factor, the RMSE's bias removed),
    // and over conditions too from kFewConditions conditions (`overConditions`); the RMSE's starts at 0 where a
    // bootstrap test of RMSE = 0 does not reject; NaN without two observers.
    double slope = 0.0, slopeLow = 0.0, slopeHigh = 0.0;
    double rmse = 0.0, rmseLow = 0.0, rmseHigh = 0.0;
    bool overConditions = false;
    int bootstrapSamples = 0;
    // Spearman's ρ, its exact two-sided p (all orderings up to 8 conditions) and an interval consistent with it at
    // few conditions (agreement::spearmanExactInterval; Fisher z with Bonett–Wright from 8).
    double spearman = 0.0, spearmanLow = 0.0, spearmanHigh = 0.0, spearmanP = 0.0;
};

struct PredictionOptions {
    int samples = 1000; // bootstrap resamples
    std::uint64_t seed = 1;
    double level = 0.95;
    skinlab::analysis::scaling::FitOptions fit; // as the scale was fitted
};

// One block: `predicted` per condition of `block` (NaN: none); `data` the block's answers (nullptr: no bootstrap).
// Nothing with fewer than 3 conditions predicted and measured.
std::optional<PredictionAgreement> blockPredictionAgreement(const skinlab::analysis::scaling::BlockAnalysis& block,
                                                            const std::vector<double>& predicted,
                                                            const skinlab::analysis::scaling::BlockData* data,
                                                            const PredictionOptions& options);

// The entries of a manifest stored in a study file (meta manifest_json), by the one strict reader of contract 2
// (formats/stimulus_manifest.h); none when it has no "stimuli".
std::vector<formats::ManifestEntry> storedManifestEntries(const nlohmann::json& manifest);

// The blocks of `analysis` whose conditions carry predictions in `manifest` (at least 3 conditions). `dataset`: the
// answers `analysis` was computed from (for the bootstrap; nullptr: none).
std::vector<PredictionAgreement> predictionAgreement(const experiments::StudyDefinition& definition,
                                                     const nlohmann::json& manifest,
                                                     const skinlab::analysis::scaling::Analysis& analysis,
                                                     const skinlab::analysis::scaling::Dataset* dataset = nullptr,
                                                     const PredictionOptions& options = {});

// Predictions with a participant's own display geometry: where an online study's card calibration recorded a
// participant's pixels per degree, each block's conditions predicted again on the set's display model with that
// ppd, and how much that changes the predictions.
struct ParticipantPrediction {
    std::string observer;
    double pixelsPerDegree = 0.0;
    double meanChange = 0.0, largestChange = 0.0; // |JOD with the participant's ppd − the set's prediction|
    bool orderChanged = false;                    // the conditions' predicted order differs in some block
    int stimuli = 0;
};

// `viewing`: (observer, pixels per degree) of the participants whose calibration recorded it. Reads the stimuli's
// PNGs from `stimuliFolder`. Empty when nothing was predicted or nobody calibrated.
std::vector<ParticipantPrediction> participantPredictions(const nlohmann::json& manifest,
                                                          const std::filesystem::path& stimuliFolder,
                                                          const std::vector<std::pair<std::string, double>>& viewing);

// The section's HTML (heading id "prediction"); empty when nothing was predicted.
// `simulatedObservers`: how many of the participants `study simulate` sent (their answers come from a given truth;
// with `--truth predicted` that truth is the prediction and the agreement is circular, which the section says).
std::string predictionSectionHtml(const std::vector<PredictionAgreement>& agreement, const std::string& display,
                                  const std::vector<ParticipantPrediction>& participants = {},
                                  int simulatedObservers = 0);

} // namespace skinlab::report
