// Every command-line error of every `skinlab` subcommand — an unknown option, a value out of range or not in the
// allowed set, a missing argument, a missing subcommand — exits with status 2 and one line on stderr (README.md),
// whatever code CLI11 gives the error; --help and --version still exit 0.
#include "tests/common/cli_run.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <sys/wait.h>
#include <vector>

namespace {

using skinlab::test_support::CliRun;
CliRun run(const std::string& arguments) { return skinlab::test_support::runCli(arguments); }

TEST(CliErrors, EverySubcommandExitsTwoWithOneLine) {
    const std::vector<std::string> cases = {
        "",                                               // no subcommand
        "--no-such-flag",                                 // unknown option of the app
        "analyze scale r.csv -o out --prior-precision 0", // value out of range (CLI11: 105)
        "analyze scale r.csv -o out --no-such-flag",      // unknown option (CLI11: 106)
        "analyze scale r.csv -o out --prior flat",        // value not in the allowed set
        "analyze scale r.csv",                            // missing required option
        "analyze scale -o out",                           // missing positional argument
        "analyze scale r.csv -o out --bootstrap ten",     // not a number
        "analyze scale r.csv -o out --columns nope=x",    // a --columns role skinlab does not know
        "analyze validate --experiments 0",               // out of range
        "analyze validate --scenarios",                   // option without its value
        "analyze",                                        // missing sub-subcommand
        "study --no-such-flag",                           // unknown option of another subcommand
        "study export",                                   // missing argument
        "render --no-such-flag",
        "kernel --no-such-flag",
        "stimuli --no-such-flag",
        "bench --no-such-flag",
        "report --no-such-flag",
        "report s.db -o out --display no-such-display", // the display options of analyze metrics, checked first
        "report s.db -o out --display-resolution 19x",  // a custom display's bad value
        "study simulate s.db --observers 3",            // the old spelling of --observer-count
        "pathtraced --no-such-flag",
        "methods --no-such-flag",
        "analyze metrics --no-such-flag",
        "analyze agreement --no-such-flag",
        "analyze seed-mean --no-such-flag",
        "analyze seed-mean a.exr -o mean.exr",                       // one seed: at least two
        "analyze seed-mean missing-a.exr missing-b.exr -o mean.exr", // unreadable seeds
        "no-such-subcommand",
    };
    for (const std::string& arguments : cases) {
        const CliRun result = run(arguments);
        EXPECT_EQ(result.exitCode, 2) << "skinlab " << arguments << "\n" << result.output;
        EXPECT_EQ(result.output.rfind("skinlab: error: ", 0), 0u) << "skinlab " << arguments << "\n" << result.output;
        ASSERT_FALSE(result.output.empty());
        EXPECT_EQ(result.output.find('\n'), result.output.size() - 1)
            << "skinlab " << arguments << ": more than one line\n"
            << result.output;
    }
}

// A misspelled option is named with the nearest option of its subcommand (or of a command above it), not as a list
// of unexpected arguments ("300 --widht", CLI11's reversed order); a plain extra word keeps CLI11's message.
TEST(CliErrors, MisspelledOptionNamesTheNearestOne) {
    CliRun result = run("render --scene builtin:head -o never.exr --widht 300");
    EXPECT_EQ(result.exitCode, 2);
    EXPECT_EQ(result.output,
              "skinlab: error: unknown option --widht (did you mean --width?); see skinlab render --help\n");
    result = run("analyze scale r.csv -o out --prior-precison 2");
    EXPECT_EQ(result.output, "skinlab: error: unknown option --prior-precison (did you mean --prior-precision?); see "
                             "skinlab analyze scale --help\n");
    result = run("methods --verbsoe");
    EXPECT_EQ(result.output, "skinlab: error: unknown option --verbsoe (did you mean --verbose?); see skinlab methods "
                             "--help\n");
    result = run("methods --no-such-flag");
    EXPECT_EQ(result.output, "skinlab: error: unknown option --no-such-flag; see skinlab methods --help\n");
    result = run("methods extra");
    EXPECT_EQ(result.exitCode, 2);
    EXPECT_NE(result.output.find("extra"), std::string::npos) << result.output;
}

TEST(CliErrors, HelpAndVersionExitZero) {
    for (const std::string arguments : {"--help", "--version", "analyze scale --help", "study --help"}) {
        const CliRun result = run(arguments);
        EXPECT_EQ(result.exitCode, 0) << "skinlab " << arguments << "\n" << result.output;
        EXPECT_FALSE(result.output.empty());
    }
}

} // namespace
