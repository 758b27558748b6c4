#pragma once
// From tuning to a study: a configuration written as a scene spec that `skinlab render` reproduces exactly, and as
// an [[include]] for a stimulus-set spec; a stimulus of a built set read back as a configuration; the kernel of a
// configuration as curves and taps for the page. docs/tuning.md.
#include "common/error.h"
#include "common/spec.h"
#include "tune/tune_engine.h"

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace skinlab::tune {

// The scene spec of `config`: the base scene's TOML with the overrides applied, relative paths of a scene file made
// absolute (so the spec renders from any folder), headed by a comment naming the base and the overrides. Validates
// the result as `skinlab render` would (InputError).
std::string exportedSceneText(const TuneConfig& config, const std::filesystem::path& assetsDir);
// An [[include]] table for a stimulus-set spec whose `set.scene` is the configuration's scene: `method = ...` and
// every other override as a scene key.
std::string includeSnippet(const TuneConfig& config);

struct ExportedFiles {
    std::filesystem::path scene;   // NAME.toml
    std::filesystem::path include; // NAME.include.toml
    std::string sceneText, includeText;
};
// Thrown by exportConfig when a file it would write exists and `overwrite` is false; nothing was written.
class ExportExists : public InputError {
public:
    explicit ExportExists(std::vector<std::filesystem::path> files);
    const std::vector<std::filesystem::path>& files() const { return files_; }

private:
    std::vector<std::filesystem::path> files_;
};

// Writes both files atomically into `folder` (created). `name`: a-z 0-9 . _ - (InputError otherwise). An existing
// file is replaced only when `overwrite` is true (ExportExists otherwise; a file appearing meanwhile is not replaced
// either).
ExportedFiles exportConfig(const TuneConfig& config, const std::filesystem::path& folder, const std::string& name,
                           const std::filesystem::path& assetsDir, bool overwrite = false);

// The TOML of a scene: builtin:NAME's text or the scene file (InputError when unreadable).
toml::table sceneTable(const std::string& scene);

// The stimulus `id` of the built set in `setFolder` (its manifest.json) as a configuration: its scene and
// overrides, exactly as `stimuli build` rendered it. A scene file is the one the build rendered (the manifest's
// resolved scene) while it exists, else the manifest's relative path taken from the manifest's folder. InputError
// naming the manifest.
TuneConfig stimulusConfig(const std::filesystem::path& setFolder, const std::string& id);
// The stimuli of a set: [{"id", "scene", "factors", "reference"}].
nlohmann::json stimulusEntries(const std::filesystem::path& setFolder);

// The kernel of the [sss] overrides of `config` (the other keys are ignored): the method's taps per stage
// (`skinlab kernel`'s JSON), and, on a common grid of radii in mm, the 1-D profile per channel of the method (the
// continuous marginal where it has one, else its taps' density), d'Eon's and Burley's skin profiles at the same
// width. InputError as the scene reader for bad [sss] values.
nlohmann::json kernelCurves(const TuneConfig& config);

} // namespace skinlab::tune
