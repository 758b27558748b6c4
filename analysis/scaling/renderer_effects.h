#pragma once
// Conditions rendered by different renderers: skinlab's rasterizer (every screen-space method, `none` and the
// object-space `reference`), Blender EEVEE (`eevee`) and Blender Cycles (`pathtraced`). Two renderers differ in
// more than SSS (EEVEE's shadow-map filtering, its eye highlights), so an SSS condition is compared with its own
// renderer's no-SSS baseline (the SSS effect within a renderer), and a direct comparison of conditions of different
// renderers carries a one-line warning (docs/pathtraced.md, "EEVEE against the rasterizer").
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace skinlab::analysis::scaling {

struct ConditionRenderer {
    std::string renderer; // "skinlab", "eevee" or "cycles"
    bool noSss = false;   // the renderer's no-SSS baseline: `none`, `eevee` with eevee.sss = false, `pathtraced`
                          // with pathtraced.sss = false
};

// From a stimulus's resolved parameters (manifest.json stimuli[].resolved); an absent sss.method is `none`.
ConditionRenderer conditionRenderer(const nlohmann::json& resolved);

// One SSS condition against its renderer's no-SSS baseline in the same block: effect = score − baseline's score.
struct SssEffect {
    std::string condition;
    std::string renderer;
    std::string baseline;
    double effect = 0.0;
};

struct RendererEffects {
    std::vector<std::string> renderers;       // in order of first appearance
    std::vector<SssEffect> effects;           // every SSS condition whose renderer has a baseline in the block
    std::vector<std::string> withoutBaseline; // SSS conditions whose renderer has none
    std::optional<std::string> warning;       // one line where the block mixes renderers
};

// Conditions of one block (names, resolved parameters, scores of equal length; InputError otherwise).
RendererEffects sssEffectsWithinRenderers(const std::string& block, const std::vector<std::string>& conditions,
                                          const std::vector<nlohmann::json>& resolved,
                                          const std::vector<double>& scores);

} // namespace skinlab::analysis::scaling
