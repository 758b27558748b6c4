// `skinlab kernel` through the real executable (label integration): JSON and CSV output, normalised taps, errors
// word for word with exit code 2.
#include <array>
#include <cstdio>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <sys/wait.h>

namespace {

struct CliRun {
    int exitCode;
    std::string out;
};

// Runs the CLI with `arguments` (shell words), capturing stdout and stderr together.
CliRun runCli(const std::string& arguments) {
    const std::string command = std::string(SKINLAB_CLI) + " " + arguments + " 2>&1";
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return {-1, "popen failed"};
    std::string out;
    std::array<char, 4096> buffer{};
    size_t n;
    while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) out.append(buffer.data(), n);
    const int status = pclose(pipe);
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

} // namespace

// The methods whose kernels run through the shared blur passes, as `skinlab methods` lists them.
std::vector<std::string> blurPassMethods() {
    const CliRun run = runCli("methods --json");
    EXPECT_EQ(run.exitCode, 0) << run.out;
    std::vector<std::string> names;
    for (const auto& row : nlohmann::json::parse(run.out))
        if (row["blur_passes"].get<bool>()) names.push_back(row["name"]);
    return names;
}

TEST(KernelCli, PrintsNormalisedTapsAsJson) {
    const std::vector<std::string> methods = blurPassMethods();
    EXPECT_EQ(methods.size(), 3u);
    for (const std::string& method : methods) {
        const CliRun run = runCli(std::string("kernel --method ") + method + " --samples 11 --stats");
        ASSERT_EQ(run.exitCode, 0) << run.out;
        const auto json = nlohmann::json::parse(run.out);
        EXPECT_EQ(json["params"]["method"], method);
        EXPECT_EQ(json["params"]["samples"], 11);
        ASSERT_FALSE(json["kernel"]["stages"].empty());
        for (const auto& stage : json["kernel"]["stages"]) {
            ASSERT_EQ(stage["taps"].size(), 11u);
            for (int c = 0; c < 3; ++c) {
                double sum = 0.0;
                for (const auto& tap : stage["taps"]) sum += tap["weight"][c].get<double>();
                EXPECT_NEAR(sum, 1.0, 1e-9) << method; // JSON keeps 17 significant digits
            }
        }
        EXPECT_EQ(json["statistics"]["stages"].size(), json["kernel"]["stages"].size());
    }
}

TEST(KernelCli, PrintsCsv) {
    const CliRun run = runCli("kernel --method artistic --samples 7 --format csv");
    ASSERT_EQ(run.exitCode, 0) << run.out;
    std::istringstream lines(run.out);
    std::string line;
    std::getline(lines, line);
    EXPECT_EQ(line, "stage,offset_mm,weight_r,weight_g,weight_b,accumulate_r,accumulate_g,accumulate_b");
    int rows = 0;
    while (std::getline(lines, line)) ++rows;
    EXPECT_EQ(rows, 7);
    EXPECT_NE(run.out.find("\n0,-2,"), std::string::npos) << run.out; // RANGE = 2 for N ≤ 20
}

TEST(KernelCli, BadInputIsOneLineWithExitCode2) {
    CliRun run = runCli("kernel --method separable --samples 20");
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_EQ(run.out,
              "skinlab: error: command line: sss.samples: 20 is even; a symmetric kernel needs an odd number of taps "
              "(3…101)\n");
    run = runCli("kernel --method separable --material marble");
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_EQ(run.out, "skinlab: error: command line: sss.material: 'marble' has no d'Eon profile (only 'skin'); use "
                       "sss.profile = \"burley\"\n");
    run = runCli("kernel --method separable --profile file:/nonexistent/k.bn");
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_EQ(run.out, "skinlab: error: command line: sss.profile: /nonexistent/k.bn: kernel file not found\n");
    run = runCli("kernel --method separable --set camera.view=close");
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_EQ(run.out, "skinlab: error: command line: camera: unknown key\n");
}

// `skinlab methods` lists the method table; a key the chosen method does not read is refused by `kernel --set` and
// by its shorthand options alike (exit 2, naming key and method).
TEST(KernelCli, MethodsTableAndKeysOfAnotherMethod) {
    const CliRun list = runCli("methods --list");
    ASSERT_EQ(list.exitCode, 0) << list.out;
    EXPECT_NE(list.out.find("separable\n"), std::string::npos);
    EXPECT_NE(list.out.find("pathtraced\n"), std::string::npos);
    const CliRun screen = runCli("methods --list --screen-space");
    EXPECT_EQ(screen.out.find("reference"), std::string::npos);
    EXPECT_NE(screen.out.find("pscbf\n"), std::string::npos);
    const CliRun bad = runCli("kernel --method separable --set 'sss.artistic_falloff=[1.0,0.5,0.5]'");
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.out.find("command line: sss.artistic_falloff: not a parameter of method 'separable'"),
              std::string::npos)
        << bad.out;
    const CliRun profile = runCli("kernel --method artistic --profile burley");
    EXPECT_EQ(profile.exitCode, 2);
    EXPECT_NE(profile.out.find("sss.profile: not a parameter of method 'artistic'"), std::string::npos) << profile.out;
}

// The table as text: `none` reads no key of its own (the common keys are listed once, after the methods), and an
// integer range reads "integer 3…101", not "3.0…101.0".
TEST(KernelCli, MethodsTextListsCommonKeysOnceAndIntegersAsIntegers) {
    const CliRun table = runCli("methods");
    ASSERT_EQ(table.exitCode, 0) << table.out;
    const std::size_t none = table.out.find("none\n");
    const std::size_t next = table.out.find("gaussian-sum  (screen-space)\n");
    ASSERT_NE(none, std::string::npos) << table.out;
    ASSERT_NE(next, std::string::npos) << table.out;
    const std::string noneBlock = table.out.substr(none, next - none);
    EXPECT_NE(noneBlock.find("keys: only the common keys\n"), std::string::npos) << noneBlock;
    EXPECT_EQ(noneBlock.find("width_mm"), std::string::npos) << noneBlock;
    std::size_t widthLines = 0;
    for (std::size_t at = table.out.find("      width_mm ("); at != std::string::npos;
         at = table.out.find("      width_mm (", at + 1))
        ++widthLines;
    EXPECT_EQ(widthLines, 1u) << table.out;
    EXPECT_NE(table.out.find("      samples (integer "), std::string::npos) << table.out;
    EXPECT_EQ(table.out.find("integer 3.0"), std::string::npos) << table.out;
    EXPECT_TRUE(std::regex_search(table.out, std::regex("samples \\(integer [0-9]+\xe2\x80\xa6[0-9]+,"))) << table.out;
}
