#include "analysis/metrics/stimulus_set_pairs.h"

#include "common/error.h"
#include "common/files.h"
#include "common/hash.h"
#include "formats/stimulus_manifest.h"

#include <algorithm>
#include <map>
#include <set>

namespace skinlab::metrics {
namespace fs = std::filesystem;

ComparisonPlan planFileComparisons(const fs::path& reference, const std::vector<fs::path>& tests) {
    ComparisonPlan plan;
    std::map<std::string, fs::path> seen;
    for (const fs::path& test : tests) {
        std::string name = test.stem().string();
        if (auto [it, inserted] = seen.emplace(name, test); !inserted)
            throwInput(test.string(), "",
                       "test name '" + name + "' repeats (" + it->second.string() +
                           "); heat maps are named after the file stem, so rename one");
        plan.jobs.push_back({reference.stem().string(), reference, name, test, "", nlohmann::json::object()});
    }
    return plan;
}

namespace {

struct StimulusEntry {
    std::string id;
    std::string block;
    fs::path exr;
    fs::path png;
    bool reference = false;
    nlohmann::json factors;
};

} // namespace

std::optional<CvvdpDisplay> ComparisonPlan::recordedDisplay() const {
    if (displayModel) return cvvdpDisplayOf(*displayModel);
    if (display) return cvvdpDisplay(*display);
    return std::nullopt;
}

ComparisonPlan planStimulusSetComparisons(const fs::path& stimulusFolder,
                                          const std::optional<std::string>& referenceId) {
    // The one strict reader of contract 2 (formats/stimulus_manifest.h).
    const formats::StimulusManifest manifest = formats::readStimulusManifest(stimulusFolder);
    const std::string& file = manifest.file;
    std::error_code ec;

    std::vector<StimulusEntry> entries;
    std::optional<std::string> display;
    std::optional<formats::DisplayModel> displayModel;
    for (size_t i = 0; i < manifest.stimuli.size(); ++i) {
        const formats::ManifestEntry& stimulus = manifest.stimuli[i];
        const std::string where = "stimuli[" + std::to_string(i) + "].";
        StimulusEntry entry;
        entry.id = stimulus.id;
        entry.block = stimulus.block;
        if (stimulus.files.exr.empty())
            throwInput(file, where + "files.exr", "missing (image metrics read the renders)");
        entry.exr = stimulusFolder / stimulus.files.exr;
        if (!stimulus.files.png.empty()) entry.png = stimulusFolder / stimulus.files.png;
        entry.reference = stimulus.reference;
        entry.factors = stimulus.factors;
        // The content hash ties the metrics to the set as built; a changed file is not silently measured.
        for (const auto& [path, expected] :
             {std::pair<fs::path, std::string>{entry.exr, stimulus.sha256.exr}, {entry.png, stimulus.sha256.png}})
            if (!path.empty() && fs::is_regular_file(path, ec) && sha256File(path) != expected)
                throwInput(path.string(), "",
                           "sha256 does not match " + file + " (the file changed after the set was built)");
        // The display the set's predictions were made for: one viewing geometry per set.
        if (stimulus.predicted && !stimulus.predicted->display.empty()) {
            const std::string& named = stimulus.predicted->display;
            if (display && *display != named)
                throwInput(file, where + "predicted.display",
                           "\"" + named + "\" differs from \"" + *display +
                               "\" of an earlier stimulus (predict the set again on one display)");
            if (display && displayModel != stimulus.predicted->displayModel)
                throwInput(file, where + "predicted.display_model",
                           "differs from the custom display of an earlier stimulus (predict the set again on one "
                           "display)");
            display = named;
            displayModel = stimulus.predicted->displayModel;
        }
        entries.push_back(std::move(entry));
    }

    // Blocks in manifest order, each with its reference.
    std::vector<std::string> blockOrder;
    std::map<std::string, std::vector<const StimulusEntry*>> members;
    for (const StimulusEntry& entry : entries) {
        if (!members.count(entry.block)) blockOrder.push_back(entry.block);
        members[entry.block].push_back(&entry);
    }
    std::map<std::string, const StimulusEntry*> references;
    if (referenceId) {
        const StimulusEntry* chosen = nullptr;
        for (const StimulusEntry& entry : entries)
            if (entry.id == *referenceId) chosen = &entry;
        if (!chosen) throwInput("--reference", "", "no stimulus '" + *referenceId + "' in " + file);
        references[chosen->block] = chosen;
    } else {
        for (const StimulusEntry& entry : entries) {
            if (!entry.reference) continue;
            if (auto [it, inserted] = references.emplace(entry.block, &entry); !inserted)
                throwInput(file, "",
                           "block '" + entry.block + "' has two reference stimuli ('" + it->second->id + "' and '" +
                               entry.id + "'); pick one with --reference ID");
        }
        if (references.empty())
            throwInput(file, "", "no stimulus has \"reference\": true; name one with --reference ID");
    }

    ComparisonPlan plan;
    plan.display = display;
    plan.displayModel = displayModel;
    // The presented images, when every stimulus lists one (a set built or imported by skinlab does).
    const bool presented =
        std::all_of(entries.begin(), entries.end(), [](const StimulusEntry& e) { return !e.png.empty(); });
    for (const std::string& block : blockOrder) {
        auto found = references.find(block);
        if (found == references.end()) {
            plan.blocksWithoutReference.push_back(block);
            continue;
        }
        const StimulusEntry* reference = found->second;
        for (const StimulusEntry* test : members[block])
            if (test != reference)
                plan.jobs.push_back({reference->id, reference->exr, test->id, test->exr, block, test->factors,
                                     presented ? reference->png : fs::path(), presented ? test->png : fs::path()});
    }
    return plan;
}

} // namespace skinlab::metrics
