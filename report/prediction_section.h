#pragma once
// The study report's "Predicted and measured" section: per block, the JOD a model of vision predicted for each
// condition (the manifest's "predicted" entries, ColorVideoVDP against the block's reference, written by
// `skinlab stimuli build`) against the JOD the observers' answers gave, both as differences to the same anchor (the
// condition predicted closest to the reference), with the identity line, the measured intervals, and the agreement:
// least-squares slope, RMSE, Spearman's ρ with its interval over the conditions.
#include "analysis/scaling/scale_analysis.h"
#include "experiments/study_definition.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace skinlab::report {

struct PredictionAgreement {
    std::string block;
    std::string anchor;
    std::vector<std::string> conditions; // with a prediction and a measurement
    std::vector<double> predicted;       // JOD difference to the anchor
    std::vector<double> measured;        // JOD difference to the anchor
    std::vector<double> low, high;       // interval of the measured difference (NaN where none)
    double slope = 0.0;                  // least squares of measured on predicted (through the anchor)
    double rmse = 0.0;                   // of measured − predicted, JOD
    double spearman = 0.0, spearmanLow = 0.0, spearmanHigh = 0.0;
};

// The blocks of `analysis` whose conditions carry predictions in `manifest` (at least 3 conditions).
std::vector<PredictionAgreement> predictionAgreement(const experiments::StudyDefinition& definition,
                                                     const nlohmann::json& manifest,
                                                     const skinlab::analysis::scaling::Analysis& analysis);

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
std::string predictionSectionHtml(const std::vector<PredictionAgreement>& agreement, const std::string& display,
                                  const std::vector<ParticipantPrediction>& participants = {});

} // namespace skinlab::report
