#pragma once
// The stimulus-set spec: a strict TOML file (docs/stimuli.md) describing which scene(s) to render, the factors
// that vary (a full factorial with exclusions, explicit extra stimuli and reference stimuli) and the scene
// parameters held fixed across the whole set (resolution, exposure, tone mapper), so that no condition is
// favoured by anything but the factor under test.
#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace skinlab::stimuli {

// One level of a factor, or one fixed value.
struct Level {
    std::string overrideText; // TOML text of the value, used in "key=value" overrides ("\"separable\"", "20")
    std::string value;        // the value as a person reads it: separable, 20, 0.5, true (manifest "factors")
    std::string label;        // id-safe label used in stimulus ids ([a-z0-9._-]): separable, samples-20
    nlohmann::json json;      // the value as JSON (typed)
};

// A factor of the factorial. `name` is what the spec calls it ("method", "sss.samples", "scene"); `key` is the
// scene-spec key it overrides ("sss.method"; empty for "scene", which picks the scene spec itself).
struct Factor {
    std::string name;
    std::string key;
    std::vector<Level> levels;
};

// A partial assignment of levels (an [[exclude]], [[include]] or [[reference]] entry): factor name → levels.
// Names that are not factors of the factorial (allowed in include/reference) are extra scene keys.
struct Selection {
    std::string where;                                              // "exclude[0]" etc., for messages
    std::vector<std::pair<std::string, std::vector<Level>>> levels; // in the order written (sorted by name)
};

struct FixedParameter {
    std::string key; // dotted scene key ("render.width")
    Level level;
};

inline constexpr int kMaxMagnification = 16;

// A crop of the rendered frame, in pixels of the render (x, y: top-left corner; y counts rows from the top).
struct CropRect {
    int x = 0;
    int y = 0;
    int width = 0;
    int height = 0;
    bool operator==(const CropRect&) const = default;
};

// How a magnified crop is made (key `presentation`): native renders the crop's part of the camera's frustum at
// magnification × the pixels (render.window of a frame magnification × the render size: an off-axis projection of the
// same camera, the SSS kernel in millimetres); replicate crops the render and repeats each pixel as a
// magnification × magnification square (nearest neighbour), which the build warns about.
enum class PresentationMethod { native, replicate };

// How the stimuli are presented: the part of the render shown and its integer magnification (the presented image
// has magnification × the crop's pixels, shown at one image pixel per device pixel). `where` names the spec key
// each value came from, for messages ("fixed.crop", "crop[1]").
struct Presentation {
    std::optional<CropRect> crop; // none: the whole frame
    int magnification = 1;
    PresentationMethod method = PresentationMethod::native;
    std::string cropWhere = "fixed.crop";
    std::string magnificationWhere = "fixed.magnification";
    std::string methodWhere = "fixed.presentation";
};

// A [[crop]] entry: the crop (and optionally the magnification) of the stimuli whose block-factor levels match.
struct CropRule {
    Selection selection; // block factors only, so that every stimulus of a block is presented alike
    std::optional<CropRect> crop;
    std::optional<int> magnification;
    std::optional<PresentationMethod> method; // presentation = "native" | "replicate"
};

struct SetSpec {
    std::filesystem::path file;       // the spec file (messages, relative scene paths)
    std::string fileName;             // as given on the command line, for messages
    std::string name;                 // set.name
    std::string description;          // set.description
    std::optional<std::int64_t> seed; // set.seed: recorded in the manifest for downstream use
    std::string idTemplate;           // set.id: "{scene}-{view}-{method}"; empty: every factor's label joined by '-'
    std::vector<std::string> blockFactors; // set.block: factors naming a block (default scene, view)
    std::vector<FixedParameter> fixed;     // [fixed], flattened to dotted keys (sorted), without crop/magnification
    Presentation presentation;             // fixed.crop, fixed.magnification and fixed.presentation
    std::vector<CropRule> crops;           // [[crop]]: per block (view, scene, ...) crops; the first match wins
    std::vector<Factor> factors;           // "scene" first, then [[factor]] in the order written
    std::vector<Selection> excludes;       // [[exclude]]
    std::vector<Selection> includes;       // [[include]]
    std::vector<Selection> references;     // [[reference]]
    std::string sha256;                    // of the spec bytes and the --set overrides
};

// Friendly factor names: "method" → "sss.method", "view" → "camera.view"; other names are scene keys as written.
std::string sceneKeyOf(const std::string& factorName);

// Scene keys that a set always holds fixed: they may appear in [fixed] but never vary.
const std::vector<std::string>& alwaysFixedKeys();

// Reads and validates a spec (strict: unknown keys, wrong types, bad levels are InputError naming file and key).
// `overrides` are "key=value" assignments applied to the spec's TOML before reading (like --set).
SetSpec readSetSpec(const std::filesystem::path& file, const std::vector<std::string>& overrides = {});
// Same, from TOML text (`file` names it in messages and anchors relative scene paths).
SetSpec readSetSpecString(std::string_view text, const std::filesystem::path& file,
                          const std::vector<std::string>& overrides = {});

} // namespace skinlab::stimuli
