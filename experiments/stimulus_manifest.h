#pragma once
// Reading a stimulus set's manifest.json (contract 2 in docs/architecture.md). The experiment runner works on any
// folder of images with such a manifest; it never calls the renderer.
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace skinlab::experiments {

struct ManifestStimulus {
    std::string id;
    std::string pngPath;   // relative to the manifest's folder, checked to stay inside it
    std::string pngSha256; // lower-case hex from the manifest
    std::string block;     // comparisons only happen within a block (e.g. "builtin:head/mid")
    bool reference = false;
    int width = 0; // image pixels
    int height = 0;
    std::map<std::string, std::string> factors; // factor name -> level (numbers are kept as their JSON text)
};

struct StimulusManifest {
    std::filesystem::path folder; // absolute folder holding manifest.json
    std::string set;
    std::string text;   // the manifest file's bytes, stored in the study
    std::string sha256; // of `text`
    std::vector<ManifestStimulus> stimuli;

    const ManifestStimulus* find(const std::string& id) const;
};

// Reads DIR/manifest.json. Throws InputError naming the file and the offending key (e.g.
// "stimuli/manifest.json: stimuli[3].files.png: path leaves the stimulus folder").
StimulusManifest readStimulusManifest(const std::filesystem::path& folder);

// Checks that every listed stimulus's PNG exists and has the manifest's sha256 (InputError otherwise).
void verifyStimulusFiles(const StimulusManifest& manifest, const std::vector<std::string>& ids);

} // namespace skinlab::experiments
