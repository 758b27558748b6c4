#include "experiments/study_creation.h"

#include "common/files.h"
#include "experiments/study_store.h"

namespace skinlab::experiments {

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
    return created;
}

} // namespace skinlab::experiments
