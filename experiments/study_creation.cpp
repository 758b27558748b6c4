#include "experiments/study_creation.h"

#include "common/files.h"
#include "experiments/study_store.h"

#include <algorithm>

namespace skinlab::experiments {

namespace {

std::vector<std::string> blocksLeftOut(const StudyDesign& design, const StimulusManifest& manifest,
                                       const StudyDefinition& definition) {
    std::vector<std::string> seen, leftOut;
    std::string designBlocks;
    for (const std::string& b : design.blocks) designBlocks += (designBlocks.empty() ? "" : ", ") + b;
    for (const ManifestStimulus& s : manifest.stimuli) {
        if (std::find(seen.begin(), seen.end(), s.block) != seen.end()) continue;
        seen.push_back(s.block);
        const bool studied = std::any_of(definition.blocks.begin(), definition.blocks.end(),
                                         [&](const StudyBlock& b) { return b.name == s.block; });
        if (studied) continue;
        const bool listed = design.blocks.empty() ||
                            std::find(design.blocks.begin(), design.blocks.end(), s.block) != design.blocks.end();
        leftOut.push_back(s.block + (listed ? " (it holds fewer than two of the design's conditions)"
                                            : " (not among the design's blocks: " + designBlocks + ")"));
    }
    return leftOut;
}

} // namespace

CreatedStudy createStudy(const std::filesystem::path& stimuliDir, const std::filesystem::path& designPath,
                         const std::vector<std::string>& overrides, const std::filesystem::path& output) {
    const StimulusManifest manifest = readStimulusManifest(stimuliDir);
    const StudyDesign design = readStudyDesign(designPath, overrides);
    CreatedStudy created;
    created.definition = resolveStudy(design, manifest);
    std::vector<std::string> ids;
    for (const StudyStimulus& s : created.definition.stimuli) ids.push_back(s.id);
    verifyStimulusFiles(manifest, ids);
    StudyStore::create(output, created.definition, readFile(designPath), manifest);
    created.trialsPerParticipant = design.practiceTrials + created.definition.testTrialCount() +
                                   created.definition.repeatTrialCount() + created.definition.catchTrialCount();
    created.blocksLeftOut = blocksLeftOut(design, manifest, created.definition);
    return created;
}

} // namespace skinlab::experiments
