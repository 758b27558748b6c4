#include "analysis/scaling/renderer_effects.h"

#include "common/error.h"

#include <algorithm>
#include <map>

namespace skinlab::analysis::scaling {
namespace {

// A boolean switch of a renderer's table (true when absent: SSS is on by default).
bool switchOn(const nlohmann::json& resolved, const char* table, const char* key) {
    if (!resolved.contains(table) || !resolved[table].is_object() || !resolved[table].contains(key)) return true;
    const nlohmann::json& value = resolved[table][key];
    return !value.is_boolean() || value.get<bool>();
}

} // namespace

ConditionRenderer conditionRenderer(const nlohmann::json& resolved) {
    std::string method = "none";
    if (resolved.is_object() && resolved.contains("sss") && resolved["sss"].is_object() &&
        resolved["sss"].contains("method") && resolved["sss"]["method"].is_string())
        method = resolved["sss"]["method"].get<std::string>();
    if (method == "eevee") return {"eevee", !switchOn(resolved, "eevee", "sss")};
    if (method == "pathtraced") return {"cycles", !switchOn(resolved, "pathtraced", "sss")};
    return {"skinlab", method == "none"};
}

RendererEffects sssEffectsWithinRenderers(const std::string& block, const std::vector<std::string>& conditions,
                                          const std::vector<nlohmann::json>& resolved,
                                          const std::vector<double>& scores) {
    if (resolved.size() != conditions.size() || scores.size() != conditions.size())
        throwInput(block, "", "conditions, resolved parameters and scores differ in number");
    RendererEffects result;
    std::vector<ConditionRenderer> renderers;
    std::map<std::string, std::size_t> baselineOf;
    for (std::size_t i = 0; i < conditions.size(); ++i) {
        renderers.push_back(conditionRenderer(resolved[i]));
        const std::string& renderer = renderers.back().renderer;
        if (std::find(result.renderers.begin(), result.renderers.end(), renderer) == result.renderers.end())
            result.renderers.push_back(renderer);
        if (renderers.back().noSss && !baselineOf.count(renderer)) baselineOf[renderer] = i;
    }
    for (std::size_t i = 0; i < conditions.size(); ++i) {
        if (renderers[i].noSss) continue;
        const auto baseline = baselineOf.find(renderers[i].renderer);
        if (baseline == baselineOf.end()) {
            result.withoutBaseline.push_back(conditions[i]);
            continue;
        }
        result.effects.push_back(
            {conditions[i], renderers[i].renderer, conditions[baseline->second], scores[i] - scores[baseline->second]});
    }
    if (result.renderers.size() > 1) {
        std::string names;
        for (const std::string& renderer : result.renderers) names += (names.empty() ? "" : ", ") + renderer;
        result.warning = block + ": conditions of different renderers (" + names +
                         ") are compared directly; their difference includes the renderers' own (shadows, specular, "
                         "eye highlights): compare each SSS condition with its renderer's no-SSS baseline instead";
    }
    return result;
}

} // namespace skinlab::analysis::scaling
