// `skinlab methods`: the SSS method table (renderer/sss/sss_params.h, methodTable()) — every method's name, whether
// it runs in the screen-space stage, and the [sss] keys it reads. Scripts ask it instead of keeping their own lists
// (docs/methods.md, "Adding a method").
#include "cli/commands.h"
#include "common/error.h"
#include "renderer/sss/sss_params.h"

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

void runMethods(const MethodsOptions& options) {
    std::string text;
    nlohmann::json table = nlohmann::json::array();
    for (const sss::MethodInfo& info : sss::methodTable()) {
        if (options.screenSpace && !info.screenSpace()) continue;
        std::vector<std::string> keys;
        for (const std::string_view key : sss::methodKeys(info.method)) keys.emplace_back(key);
        if (options.list) {
            text += std::string(info.name) + "\n";
        } else if (options.json) {
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
        } else {
            text += std::string(info.name) + (info.screenSpace() ? "  (screen-space)" : "") + "\n    " +
                    std::string(info.summary) + "\n    keys:";
            for (const auto& key : keys) text += " " + key;
            text += "\n";
            const nlohmann::json defaults = sss::sssKeyDefaults(info.method);
            for (const auto& key : keys) {
                const sss::KeyInfo& declaration = sss::sssKey(key);
                text += "      " + key + " (" + std::string(sss::keyTypeName(declaration.type));
                if (declaration.type == sss::KeyType::Choice) {
                    text += ":";
                    for (const auto& choice : declaration.choices) text += " " + choice;
                } else if (declaration.type != sss::KeyType::Boolean && declaration.type != sss::KeyType::String) {
                    text += " " + nlohmann::json(declaration.min).dump() + "…" + nlohmann::json(declaration.max).dump();
                }
                if (!declaration.unit.empty()) text += ", " + std::string(declaration.unit);
                text += ", default " + defaults.at(key).dump() + "): " + std::string(declaration.doc) + "\n";
            }
        }
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
