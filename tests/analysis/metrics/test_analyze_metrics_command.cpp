// `skinlab analyze metrics` as a user runs it: the real executable on EXR files and on a stimulus set.
#include "common/files.h"
#include "common/hash.h"
#include "synthetic_render.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <sys/wait.h>

#include <nlohmann/json.hpp>
#include <unistd.h>

namespace skinlab::metrics {
namespace {
namespace fs = std::filesystem;

struct CommandResult {
    int exitCode = -1;
    std::string output; // stdout and stderr together
};

CommandResult runSkinlab(const std::string& arguments) {
    std::string command = std::string("'") + SKINLAB_CLI + "' " + arguments + " 2>&1";
    CommandResult result;
    FILE* pipe = ::popen(command.c_str(), "r");
    if (!pipe) return result;
    char buffer[4096];
    size_t read = 0;
    while ((read = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) result.output.append(buffer, read);
    int status = ::pclose(pipe);
    result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return result;
}

class AnalyzeMetricsCommand : public ::testing::Test {
protected:
    void SetUp() override {
        folder =
            fs::temp_directory_path() / ("skinlab-metrics-cli-" + std::to_string(::getpid()) + "-" +
                                         std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
        fs::remove_all(folder);
        fs::create_directories(folder / "exr");
        scene.size = 128;
        scene.stripeHalfWidth = 0.02;
        reference = testing::renderDiscScene(scene);
        blurred = reference;
        blurred.beauty = reference.beauty.clone();
        // A crude screen-space "halo": blend toward the far plane colour inside a ring around the silhouette.
        for (int y = 0; y < scene.size; ++y)
            for (int x = 0; x < scene.size; ++x) {
                testing::DiscPixel pixel = testing::discPixel(scene, x, y);
                double fromRim = std::fabs(std::hypot(pixel.worldX, pixel.worldY) - scene.discRadius);
                if (pixel.onDisc && fromRim < 0.005) blurred.beauty.at<cv::Vec3f>(y, x) = {0.45f, 0.35f, 0.32f};
            }
    }
    std::string path(const std::string& name) const { return (folder / name).string(); }
    fs::path folder;
    testing::DiscScene scene;
    testing::SyntheticRender reference;
    testing::SyntheticRender blurred;
};

TEST_F(AnalyzeMetricsCommand, ComparesFilesAndWritesAllOutputs) {
    testing::writeSyntheticExr(path("exr/reference.exr"), reference);
    testing::writeSyntheticExr(path("exr/same.exr"), reference);
    testing::writeSyntheticExr(path("exr/halo.exr"), blurred);
    CommandResult run = runSkinlab("analyze metrics --reference " + path("exr/reference.exr") + " " +
                                   path("exr/same.exr") + " " + path("exr/halo.exr") + " -o " + path("out"));
    ASSERT_EQ(run.exitCode, 0) << run.output;
    nlohmann::json json = nlohmann::json::parse(readFile(path("out/metrics.json")));
    ASSERT_EQ(json["comparisons"].size(), 2u);
    const auto& same = json["comparisons"][0]["bands"];
    const auto& halo = json["comparisons"][1]["bands"];
    EXPECT_EQ(same["halo"]["leak_energy"], 0.0);
    // The error sits at the silhouette: the halo band scores it, the interior does not.
    EXPECT_GT(halo["halo"]["leak_energy"].get<double>(), 0.0);
    EXPECT_GT(halo["halo"]["excess"].get<double>(), 1.0);
    EXPECT_EQ(halo["interior"]["delta_e00_mean"], 0.0);
    EXPECT_TRUE(fs::exists(path("out/metrics.csv")));
    EXPECT_TRUE(fs::exists(path("out/heatmaps/halo.png")));
    EXPECT_TRUE(fs::exists(path("out/heatmaps/same.png")));
}

TEST_F(AnalyzeMetricsCommand, ComparesAStimulusSet) {
    nlohmann::json manifest = {
        {"format", "skinlab-stimuli"}, {"version", 1}, {"set", "cli"}, {"stimuli", nlohmann::json::array()}};
    for (auto [id, render, isReference] :
         {std::tuple{"disc-reference", &reference, true}, std::tuple{"disc-separable", &blurred, false}}) {
        std::string exr = std::string("exr/") + id + ".exr";
        testing::writeSyntheticExr(path(exr), *render);
        manifest["stimuli"].push_back({{"id", id},
                                       {"files", {{"exr", exr}}},
                                       {"sha256", {{"exr", sha256File(path(exr))}}},
                                       {"factors", {{"method", id}}},
                                       {"block", "builtin:disc/mid"},
                                       {"reference", isReference}});
    }
    writeFileAtomic(path("manifest.json"), manifest.dump(2));
    CommandResult run =
        runSkinlab("analyze metrics --stimuli " + folder.string() + " -o " + path("out") + " --no-heatmaps");
    ASSERT_EQ(run.exitCode, 0) << run.output;
    nlohmann::json json = nlohmann::json::parse(readFile(path("out/metrics.json")));
    ASSERT_EQ(json["comparisons"].size(), 1u);
    EXPECT_EQ(json["comparisons"][0]["test"]["name"], "disc-separable");
    EXPECT_EQ(json["comparisons"][0]["block"], "builtin:disc/mid");
    EXPECT_TRUE(json["comparisons"][0]["heatmap"].is_null());
    EXPECT_FALSE(fs::exists(path("out/heatmaps")));
}

// Bad input: exit code 2 and exactly one line naming the file and the channel, attribute or size at fault.
TEST_F(AnalyzeMetricsCommand, BadInputsFailWithOneLineNamingFileAndChannel) {
    testing::writeSyntheticExr(path("exr/reference.exr"), reference);
    testing::writeSyntheticExr(path("exr/no-depth.exr"), reference, {{"depth.Z"}, {}});
    testing::writeSyntheticExr(path("exr/no-green.exr"), reference, {{"G"}, {}});
    testing::writeSyntheticExr(path("exr/no-scale.exr"), reference, {{}, {"skinlab:mm_per_unit"}});
    testing::DiscScene small = scene;
    small.size = 100;
    testing::writeSyntheticExr(path("exr/small.exr"), testing::renderDiscScene(small));
    const std::string out = " -o " + path("out");
    struct Case {
        std::string arguments;
        std::string message;
    };
    const Case cases[] = {
        {"--reference " + path("exr/reference.exr") + " " + path("exr/missing.exr"),
         path("exr/missing.exr") + ": file not found"},
        {"--reference " + path("exr/no-depth.exr") + " " + path("exr/reference.exr"),
         path("exr/no-depth.exr") + ": depth.Z: channel is missing"},
        {"--reference " + path("exr/reference.exr") + " " + path("exr/no-green.exr"),
         path("exr/no-green.exr") + ": G: channel is missing"},
        {"--reference " + path("exr/no-scale.exr") + " " + path("exr/reference.exr"),
         path("exr/no-scale.exr") + ": skinlab:mm_per_unit: metadata attribute is missing"},
        {"--reference " + path("exr/reference.exr") + " " + path("exr/small.exr"),
         path("exr/small.exr") + ": size 100x100 differs from the reference " + path("exr/reference.exr") +
             " (128x128)"},
        {"--reference " + path("exr/reference.exr"),
         "TEST.exr: required: at least one render to compare with the reference"},
        {path("exr/reference.exr"), "--reference: required: the reference EXR (or use --stimuli DIR)"},
        {"--stimuli " + folder.string() + " " + path("exr/reference.exr"),
         path("exr/reference.exr") + ": test files cannot be combined with --stimuli (the set lists its renders)"},
        {"--reference " + path("exr/reference.exr") + " " + path("exr/reference.exr") + " --exposure -1",
         "--exposure: -1 must be a positive number"},
    };
    for (const Case& c : cases) {
        CommandResult run = runSkinlab("analyze metrics " + c.arguments + out);
        EXPECT_EQ(run.exitCode, 2) << c.arguments << "\n" << run.output;
        EXPECT_EQ(run.output, "skinlab: error: " + c.message + "\n") << c.arguments;
        EXPECT_FALSE(fs::exists(path("out"))) << c.arguments << ": checked before anything is written";
    }
}

} // namespace
} // namespace skinlab::metrics
