#include "analysis/metrics/stimulus_set_pairs.h"

#include "common/error.h"
#include "common/files.h"
#include "common/hash.h"

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

const nlohmann::json& member(const nlohmann::json& object, const std::string& key, const std::string& file,
                             const std::string& where) {
    if (!object.is_object() || !object.contains(key)) throwInput(file, where + key, "missing");
    return object.at(key);
}

std::string stringMember(const nlohmann::json& object, const std::string& key, const std::string& file,
                         const std::string& where) {
    const nlohmann::json& value = member(object, key, file, where);
    if (!value.is_string()) throwInput(file, where + key, "must be a string");
    return value.get<std::string>();
}

} // namespace

ComparisonPlan planStimulusSetComparisons(const fs::path& stimulusFolder,
                                          const std::optional<std::string>& referenceId) {
    const fs::path manifestPath = stimulusFolder / "manifest.json";
    const std::string file = manifestPath.string();
    std::error_code ec;
    if (!fs::is_regular_file(manifestPath, ec)) throwInput(file, "", "file not found (is this a stimulus set folder?)");
    nlohmann::json manifest;
    try {
        manifest = nlohmann::json::parse(readFile(manifestPath));
    } catch (const nlohmann::json::parse_error& e) {
        throwInput(file, "", std::string("not valid JSON (") + e.what() + ")");
    }
    if (stringMember(manifest, "format", file, "") != "skinlab-stimuli")
        throwInput(file, "format", "expected \"skinlab-stimuli\"");
    const nlohmann::json& version = member(manifest, "version", file, "");
    if (!version.is_number_integer() || version.get<int>() != 1)
        throwInput(file, "version", version.dump() + " is not supported (this skinlab reads version 1)");
    const nlohmann::json& stimuli = member(manifest, "stimuli", file, "");
    if (!stimuli.is_array()) throwInput(file, "stimuli", "must be an array");

    std::vector<StimulusEntry> entries;
    std::set<std::string> ids;
    std::optional<std::string> display;
    for (size_t i = 0; i < stimuli.size(); ++i) {
        const nlohmann::json& stimulus = stimuli[i];
        const std::string where = "stimuli[" + std::to_string(i) + "].";
        StimulusEntry entry;
        entry.id = stringMember(stimulus, "id", file, where);
        if (!ids.insert(entry.id).second) throwInput(file, where + "id", "'" + entry.id + "' repeats");
        entry.block = stringMember(stimulus, "block", file, where);
        const nlohmann::json& files = member(stimulus, "files", file, where);
        std::string exr = stringMember(files, "exr", file, where + "files.");
        entry.exr = stimulusFolder / exr;
        if (files.contains("png")) entry.png = stimulusFolder / stringMember(files, "png", file, where + "files.");
        if (stimulus.contains("reference")) {
            if (!stimulus["reference"].is_boolean()) throwInput(file, where + "reference", "must be true or false");
            entry.reference = stimulus["reference"].get<bool>();
        }
        entry.factors = stimulus.contains("factors") ? stimulus["factors"] : nlohmann::json::object();
        // The content hash ties the metrics to the set as built; a changed file is not silently measured.
        for (const auto& [kind, path] : {std::pair<std::string, fs::path>{"exr", entry.exr}, {"png", entry.png}}) {
            if (path.empty() || !stimulus.contains("sha256") || !stimulus["sha256"].contains(kind)) continue;
            const nlohmann::json& expected = stimulus["sha256"][kind];
            if (!expected.is_string()) throwInput(file, where + "sha256." + kind, "must be a string");
            if (fs::is_regular_file(path, ec) && sha256File(path) != expected.get<std::string>())
                throwInput(path.string(), "",
                           "sha256 does not match " + file + " (the file changed after the set was built)");
        }
        // The display the set's predictions were made for: one viewing geometry per set.
        if (stimulus.contains("predicted") && stimulus["predicted"].is_object() &&
            stimulus["predicted"].contains("display")) {
            const nlohmann::json& named = stimulus["predicted"]["display"];
            if (!named.is_string()) throwInput(file, where + "predicted.display", "must be a string");
            if (display && *display != named.get<std::string>())
                throwInput(file, where + "predicted.display",
                           "\"" + named.get<std::string>() + "\" differs from \"" + *display +
                               "\" of an earlier stimulus (predict the set again on one display)");
            display = named.get<std::string>();
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
