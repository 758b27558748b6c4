// `skinlab methods`: the SSS method table (renderer/sss/sss_params.h, methodTable()) — every method's name, whether
// it runs in the screen-space stage, and the [sss] keys it reads (as text: each method's own keys, then the keys
// common to every method once). Scripts ask it instead of keeping their own lists
// (docs/methods.md, "Adding a method").
#include "cli/commands.h"
#include "common/error.h"
#include "renderer/sss/sss_params.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

namespace skinlab::cli {

namespace {

namespace sss = renderer::sss;

struct MethodsOptions {
    bool list = false;
    bool screenSpace = false;
    bool json = false;
};

// One key's declaration: "      samples (integer 3…101, default 25): taps per pass".
std::string keyLine(const std::string& key, const nlohmann::json& defaults) {
    const sss::KeyInfo& declaration = sss::sssKey(key);
    std::string text = "      " + key + " (" + std::string(sss::keyTypeName(declaration.type));
    if (declaration.type == sss::KeyType::Choice) {
        text += ":";
        for (const auto& choice : declaration.choices) text += " " + choice;
    } else if (declaration.type == sss::KeyType::Integer) {
        text +=
            " " + std::to_string(std::llround(declaration.min)) + "…" + std::to_string(std::llround(declaration.max));
    } else if (declaration.type != sss::KeyType::Boolean && declaration.type != sss::KeyType::String) {
        text += " " + nlohmann::json(declaration.min).dump() + "…" + nlohmann::json(declaration.max).dump();
    }
    if (!declaration.unit.empty()) text += ", " + std::string(declaration.unit);
    return text + ", default " + defaults.at(key).dump() + "): " + std::string(declaration.doc) + "\n";
}

bool isCommonKey(std::string_view key) {
    return std::find(sss::kCommonSssKeys.begin(), sss::kCommonSssKeys.end(), key) != sss::kCommonSssKeys.end();
}

// The table as text: each method with the keys only some methods read, then the common keys once (every method
// accepts them; the lighting passes read them whatever the method).
std::string methodsText(bool screenSpaceOnly) {
    std::string text;
    for (const sss::MethodInfo& info : sss::methodTable()) {
        if (screenSpaceOnly && !info.screenSpace()) continue;
        const nlohmann::json defaults = sss::sssKeyDefaults(info.method);
        std::vector<std::string> keys;
        for (const std::string_view key : sss::methodKeys(info.method))
            if (!isCommonKey(key)) keys.emplace_back(key);
        text += std::string(info.name) + (info.screenSpace() ? "  (screen-space)" : "") + "\n    " +
                std::string(info.summary) + "\n    keys:";
        for (const auto& key : keys) text += " " + key;
        text += keys.empty() ? " only the common keys\n" : " and the common keys\n";
        for (const auto& key : keys) text += keyLine(key, defaults);
    }
    text += "common keys (every method; the lighting passes read them whatever the method: width_mm for "
            "transmittance, the curvature keys for the curvature AOV):\n";
    const nlohmann::json defaults = sss::sssKeyDefaults(sss::SssMethod{});
    for (const std::string_view key : sss::kCommonSssKeys)
        if (key != "method") text += keyLine(std::string(key), defaults);
    return text;
}

void runMethods(const MethodsOptions& options) {
    if (!options.list && !options.json) {
        std::fputs(methodsText(options.screenSpace).c_str(), stdout);
        return;
    }
    std::string text;
    nlohmann::json table = nlohmann::json::array();
    for (const sss::MethodInfo& info : sss::methodTable()) {
        if (options.screenSpace && !info.screenSpace()) continue;
        std::vector<std::string> keys;
        for (const std::string_view key : sss::methodKeys(info.method)) keys.emplace_back(key);
        if (options.list) {
            text += std::string(info.name) + "\n";
            continue;
        }
        // Each key's declaration (type, range, choices, unit, doc: the reader's own) and its default.
        const nlohmann::json defaults = sss::sssKeyDefaults(info.method);
        nlohmann::json parameters = nlohmann::json::array();
        for (const auto& key : keys) {
            nlohmann::json declaration = sss::keyInfoJson(sss::sssKey(key));
            declaration["default"] = defaults.at(key);
            parameters.push_back(declaration);
        }
        table.push_back({{"name", info.name},
                         {"screen_space", info.screenSpace()},
                         {"blur_passes", info.blurPasses()},
                         {"execution", sss::executionName(info.execution)},
                         {"summary", info.summary},
                         {"keys", keys},
                         {"parameters", parameters}});
    }
    if (options.json) text = table.dump(2) + "\n";
    std::fputs(text.c_str(), stdout);
}

} // namespace

void registerMethods(CLI::App& app) {
    auto options = std::make_shared<MethodsOptions>();
    CLI::App* methods = app.add_subcommand(
        "methods", "List the SSS methods (sss.method): name, screen-space or not, and the [sss] keys each reads");
    methods->add_flag("--list", options->list, "Names only, one per line (for scripts)");
    methods->add_flag("--screen-space", options->screenSpace,
                      "Only the methods the screen-space SSS stage runs (tap kernels on the frame's buffers)");
    methods->add_flag("--json", options->json,
                      "The table as JSON: name, screen_space, blur_passes, summary, keys, parameters (declarations)");
    methods->callback([options] {
        if (options->list && options->json) throw InputError("--list and --json: give one of them");
        runMethods(*options);
    });
}

} // namespace skinlab::cli
