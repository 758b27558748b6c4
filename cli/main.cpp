// skinlab — perceptual evaluation and experiment harness for real-time skin rendering.
#include "cli/commands.h"
#include "common/error.h"
#include "common/version.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

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
