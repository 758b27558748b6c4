#pragma once
// `skinlab study create`: a stimulus folder + a design file → a new study.db.
#include "experiments/study_definition.h"

#include <filesystem>
#include <string>
#include <vector>

namespace skinlab::experiments {

struct CreatedStudy {
    StudyDefinition definition;
    int trialsPerParticipant = 0; // practice + test + repeat + catch
    // The stimulus set's blocks the study leaves out, each with the reason: "mid (not among the design's blocks:
    // close, explicit)", "far (it holds fewer than two of the design's conditions)".
    std::vector<std::string> blocksLeftOut;
};

// Reads DIR/manifest.json and the design (with --set overrides), checks the images against their hashes, and
// writes the study file atomically. Throws InputError naming the file/key at fault; nothing is written then.
CreatedStudy createStudy(const std::filesystem::path& stimuliDir, const std::filesystem::path& designPath,
                         const std::vector<std::string>& overrides, const std::filesystem::path& output);

} // namespace skinlab::experiments
