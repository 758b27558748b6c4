// skinlab — perceptual evaluation and experiment harness for real-time skin rendering.
#include "cli/commands.h"
#include "common/error.h"
#include "common/spec.h"
#include "common/version.h"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

namespace {

// An argument CLI11 did not expect that looks like an option (the value after it is not mentioned): "unknown option
// --widht (did you mean --width?); see skinlab render --help", naming the nearest option of the subcommand or of a
// command above it. std::nullopt when every unexpected argument is a plain word (CLI11's own message then).
std::optional<std::string> unknownOptionMessage(const CLI::App& app) {
    std::vector<const CLI::App*> chain{&app};
    while (!chain.back()->get_subcommands().empty()) chain.push_back(chain.back()->get_subcommands().front());
    for (auto at = chain.rbegin(); at != chain.rend(); ++at) {
        for (const std::string& argument : (*at)->remaining(false)) {
            if (argument.size() < 2 || argument[0] != '-' || (argument[1] >= '0' && argument[1] <= '9')) continue;
            const std::string name = argument.substr(0, argument.find('='));
            std::vector<std::string> known;
            std::string command;
            for (const CLI::App* a = *at; a != nullptr; a = a->get_parent()) {
                command = a->get_parent() ? a->get_name() + (command.empty() ? "" : " " + command) : command;
                for (const CLI::Option* option : a->get_options()) {
                    for (const std::string& l : option->get_lnames()) known.push_back("--" + l);
                    for (const std::string& s : option->get_snames()) known.push_back("-" + s);
                }
            }
            const std::string hint = skinlab::nearestKey(name, known);
            return "unknown option " + name + (hint.empty() ? "" : " (did you mean " + hint + "?)") + "; see skinlab " +
                   (command.empty() ? "" : command + " ") + "--help";
        }
    }
    return std::nullopt;
}

} // namespace

int main(int argc, char** argv) {
    auto logger = spdlog::stderr_color_mt("skinlab");
    spdlog::set_default_logger(logger);
    spdlog::set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");

    CLI::App app{"skinlab " + skinlab::version() +
                 " — render skin stimuli with screen-space SSS methods, run 2AFC studies, analyse them"};
    app.set_version_flag("--version", skinlab::version());
    app.require_subcommand(1);
    bool verbose = false;
    app.add_flag("-v,--verbose", verbose, "Debug logging");
    app.parse_complete_callback([&] {
        if (verbose) spdlog::set_level(spdlog::level::debug);
    });

    skinlab::cli::registerRender(app);
    skinlab::cli::registerKernel(app);
    skinlab::cli::registerStimuli(app);
    skinlab::cli::registerStudy(app);
    skinlab::cli::registerAnalyze(app);
    skinlab::cli::registerReport(app);
    skinlab::cli::registerPathtraced(app);
    skinlab::cli::registerMethods(app);
    skinlab::cli::registerTune(app);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ExtrasError& e) {
        std::string message = e.what();
        std::replace(message.begin(), message.end(), '\n', ' ');
        const std::optional<std::string> unknown = unknownOptionMessage(app);
        if (unknown) std::fprintf(stderr, "skinlab: error: %s\n", unknown->c_str());
        else std::fprintf(stderr, "skinlab: error: %s (see --help)\n", message.c_str());
        return 2;
    } catch (const CLI::ParseError& e) {
        // --help and --version end the parse with exit code 0: CLI11 prints them. Every other parse error (an
        // unknown option, a bad or missing value, a missing subcommand) is a command-line error: one line, exit 2,
        // whatever CLI11's own code for it.
        if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
        std::string message = e.what();
        std::replace(message.begin(), message.end(), '\n', ' ');
        std::fprintf(stderr, "skinlab: error: %s (see --help)\n", message.c_str());
        return 2;
    } catch (const skinlab::InputError& e) {
        std::fprintf(stderr, "skinlab: error: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "skinlab: failure: %s\n", e.what());
        return 1;
    }
    return 0;
}
