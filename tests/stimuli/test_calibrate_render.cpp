// `skinlab stimuli calibrate` through the real CLI and renderer (EGL, llvmpipe without a GPU) at 96×64:
//  - sss.width_mm of the separable method on builtin:bleed, calibrated to 0.5 JOD from the spec's [[reference]] (the
//    same scene without SSS; at 96×64 on the standard_fhd display, 100 mm gives about 1 JOD); the written [[factor]] snippet is pasted into the spec, the set is built, and
//    ColorVideoVDP on the built PNGs must give the target within the tolerance;
//  - a custom display (--display-*) is the one predicted on and named in the output;
//  - bad input (a key that is not numeric, a bad number, a reference level inside the range) fails with one line
//    naming the option and exit status 2, before anything is rendered.
// Skips with a message when no EGL platform works.
#include "analysis/metrics/cvvdp.h"
#include "analysis/metrics/metric_render.h"
#include "renderer/renderer.h"

#include <cstdio>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sstream>
#include <sys/wait.h>
#include <toml++/toml.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

struct CliRun {
    int exitCode = -1;
    std::string output; // stdout + stderr
};

CliRun runCli(const std::vector<std::string>& args, const fs::path& log) {
    pid_t pid = ::fork();
    if (pid == 0) {
        int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        ::dup2(fd, 1);
        ::dup2(fd, 2);
        std::vector<char*> argv;
        std::string cli = SKINLAB_CLI;
        argv.push_back(cli.data());
        std::vector<std::string> copy = args;
        for (auto& a : copy) argv.push_back(a.data());
        argv.push_back(nullptr);
        ::execv(cli.c_str(), argv.data());
        ::_exit(127);
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    CliRun run;
    run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    std::ifstream in(log);
    std::stringstream ss;
    ss << in.rdbuf();
    run.output = ss.str();
    return run;
}

const char* kSpec = R"([set]
name = "calibrate-bleed"
scene = "builtin:bleed"

[fixed]
render = { width = 96, height = 64, exposure_ev = 0.0 }
tone_map = { operator = "filmic" }
shadow = { resolution = 256 }

[[factor]]
name = "method"
levels = ["separable"]

[[reference]]
method = "none"
)";

class StimuliCalibrate : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        try {
            skinlab::renderer::Renderer renderer;
            available_ = true;
        } catch (const std::exception& e) {
            reason_ = e.what();
        }
    }
    void SetUp() override {
        if (!available_) GTEST_SKIP() << "no EGL/OpenGL 4.5 renderer available: " << reason_;
        root_ = fs::path(SKINLAB_BINARY_DIR) / "tests-tmp" / "stimuli-calibrate" /
                ::testing::UnitTest::GetInstance()->current_test_info()->name();
        fs::remove_all(root_);
        fs::create_directories(root_);
        spec_ = root_ / "bleed.toml";
        std::ofstream(spec_) << kSpec;
    }
    CliRun run(const std::vector<std::string>& args) { return runCli(args, root_ / "cli.log"); }

    fs::path root_, spec_;
    static inline bool available_ = false;
    static inline std::string reason_;
};

TEST_F(StimuliCalibrate, CalibratedLevelGivesTheTargetDifferenceInTheBuiltSet) {
    const double target = 0.5, tolerance = 0.05;
    const fs::path levels = root_ / "levels.toml";
    CliRun calibrate = run({"stimuli", "calibrate", spec_.string(), "--factor", "sss.width_mm", "--range", "0.25,100",
                            "--target-jod", "0.5", "--tolerance", "0.05", "-o", levels.string()});
    ASSERT_EQ(calibrate.exitCode, 0) << calibrate.output;
    EXPECT_NE(calibrate.output.find("renders:"), std::string::npos) << calibrate.output;
    EXPECT_EQ(calibrate.output.find("NOT REACHED"), std::string::npos) << calibrate.output;

    // The snippet is a [[factor]] with one level in the range.
    toml::table snippet = toml::parse_file(levels.string());
    const toml::array* factors = snippet["factor"].as_array();
    ASSERT_TRUE(factors && factors->size() == 1) << calibrate.output;
    const toml::table& factor = *factors->get(0)->as_table();
    EXPECT_EQ(factor["name"].value<std::string>(), "sss.width_mm");
    const toml::array* values = factor["levels"].as_array();
    ASSERT_TRUE(values && values->size() == 1);
    const double width = values->get(0)->value<double>().value();
    EXPECT_GT(width, 0.25);
    EXPECT_LT(width, 100.0);

    // Pasted into the spec, built, and predicted again from the set's own PNGs.
    std::ifstream in(levels);
    std::stringstream text;
    text << in.rdbuf();
    const fs::path spec2 = root_ / "bleed-calibrated.toml";
    std::ofstream(spec2) << kSpec << "\n" << text.str();
    const fs::path set = root_ / "set";
    CliRun build = run({"stimuli", "build", spec2.string(), "-o", set.string(), "--no-contact-sheet"});
    ASSERT_EQ(build.exitCode, 0) << build.output;
    std::ifstream manifestFile(set / "manifest.json");
    const nlohmann::json manifest = nlohmann::json::parse(manifestFile);
    fs::path referencePng, testPng;
    for (const auto& s : manifest["stimuli"])
        (s["reference"].get<bool>() ? referencePng : testPng) = set / s["files"]["png"].get<std::string>();
    ASSERT_FALSE(referencePng.empty());
    ASSERT_FALSE(testPng.empty());
    using namespace skinlab::metrics;
    const auto reference = loadMetricRender(referencePng, RenderRole::test, ImageEncoding::srgb);
    const auto test = loadMetricRender(testPng, RenderRole::test, ImageEncoding::srgb);
    const double jod = cvvdp(reference.beauty, test.beauty, cvvdpDisplay("standard_fhd"), false).jod;
    EXPECT_NEAR(10.0 - jod, target, tolerance) << "width_mm " << width << "\n" << calibrate.output;
}

// A custom display (--display-*, as in `stimuli build` and `analyze metrics`) is the one predicted on and named.
TEST_F(StimuliCalibrate, CustomDisplayIsTheOnePredictedOn) {
    const fs::path levels = root_ / "levels-custom.toml";
    CliRun calibrate =
        run({"stimuli", "calibrate", spec_.string(), "--factor", "sss.width_mm", "--range", "0.25,100", "--target-jod",
             "0.5", "--max-probes", "1", "--display-ppd", "20", "--display-peak", "500", "-o", levels.string()});
    ASSERT_EQ(calibrate.exitCode, 0) << calibrate.output;
    EXPECT_NE(calibrate.output.find("display custom: 20 pixels/degree, peak 500 cd/m²"), std::string::npos)
        << calibrate.output;
    std::ifstream in(levels);
    std::stringstream text;
    text << in.rdbuf();
    EXPECT_NE(text.str().find("# display custom: 20 pixels/degree, peak 500 cd/m²"), std::string::npos) << text.str();
}

TEST_F(StimuliCalibrate, BadInputIsOneLineNamingTheOption) {
    struct Case {
        std::vector<std::string> extra;
        std::string names;
    };
    const std::vector<Case> cases = {
        {{"--factor", "sss.method", "--target-jod", "1", "--range", "0,1"}, "--factor"},
        {{"--factor", "render.exposure_ev", "--target-jod", "1", "--range", "-1,1"}, "--factor"},
        {{"--factor", "sss.width_mm", "--target-jod", "1,x", "--range", "0.5,4"}, "--target-jod"},
        {{"--factor", "sss.width_mm", "--target-jod", "1", "--range", "4"}, "--range"},
        {{"--factor", "sss.width_mm", "--target-jod", "1"}, "--range"},
        {{"--factor", "sss.width_mm", "--target-jod", "1", "--range", "0.5,4", "--reference-level", "1"},
         "--reference-level"},
        {{"--factor", "sss.width_mm", "--target-jod", "1", "--range", "0.5,4", "--tolerance", "0"}, "--tolerance"},
        {{"--factor", "sss.artistic_strength", "--target-jod", "1", "--range", "0,1"}, "--factor"},
        {{"--factor", "sss.width_mm", "--target-jod", "1", "--range", "0.5,4", "--stimulus", "nope"}, "--stimulus"},
        {{"--factor", "sss.width_mm", "--target-jod", "1", "--range", "0.5,4", "--display", "nope"}, "--display"},
        {{"--factor", "sss.width_mm", "--target-jod", "1", "--range", "0.5,4", "--display-contrast", "0.5"},
         "--display-contrast: 0.5 must be a number >= 1"},
    };
    for (const auto& c : cases) {
        std::vector<std::string> args = {"stimuli", "calibrate", spec_.string()};
        args.insert(args.end(), c.extra.begin(), c.extra.end());
        CliRun r = run(args);
        EXPECT_EQ(r.exitCode, 2) << c.names << ": " << r.output;
        EXPECT_NE(r.output.find(c.names), std::string::npos) << r.output;
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    }
}

} // namespace
