#include "experiments/stimulus_manifest.h"

#include "common/error.h"
#include "common/files.h"
#include "common/hash.h"
#include "formats/stimulus_manifest.h"

namespace skinlab::experiments {
namespace fs = std::filesystem;

const ManifestStimulus* StimulusManifest::find(const std::string& id) const {
    for (const ManifestStimulus& s : stimuli)
        if (s.id == id) return &s;
    return nullptr;
}

// The one strict reader (formats/stimulus_manifest.h), then what a study needs of each entry.
StimulusManifest readStimulusManifest(const fs::path& folder) {
    const formats::StimulusManifest read = formats::readStimulusManifest(folder);
    if (read.stimuli.empty()) throwInput(read.file, "stimuli", "expected a non-empty array");
    StimulusManifest manifest;
    manifest.folder = read.folder;
    manifest.set = read.set;
    manifest.text = read.text;
    manifest.sha256 = read.sha256;
    for (std::size_t i = 0; i < read.stimuli.size(); ++i) {
        const formats::ManifestEntry& entry = read.stimuli[i];
        if (entry.files.png.empty())
            throwInput(read.file, "stimuli[" + std::to_string(i) + "].files.png", "missing (a study shows the PNGs)");
        ManifestStimulus s;
        s.id = entry.id;
        s.pngPath = entry.files.png;
        s.pngSha256 = entry.sha256.png;
        s.block = entry.block;
        s.reference = entry.reference;
        s.width = entry.width;
        s.height = entry.height;
        for (auto it = entry.factors.begin(); it != entry.factors.end(); ++it)
            s.factors[it.key()] = entry.factorText(it.key());
        manifest.stimuli.push_back(std::move(s));
    }
    return manifest;
}

void verifyStimulusFiles(const StimulusManifest& manifest, const std::vector<std::string>& ids) {
    for (const std::string& id : ids) {
        const ManifestStimulus* s = manifest.find(id);
        if (!s)
            throwInput((manifest.folder / "manifest.json").string(), "stimuli", "no stimulus with id \"" + id + "\"");
        const fs::path png = manifest.folder / s->pngPath;
        if (!fs::is_regular_file(png)) throwInput(png.string(), "", "stimulus image missing (stimulus \"" + id + "\")");
        if (sha256File(png) != s->pngSha256)
            throwInput(png.string(), "",
                       "sha256 differs from the manifest (stimulus \"" + id +
                           "\"); the set changed after it was built");
    }
}

} // namespace skinlab::experiments
