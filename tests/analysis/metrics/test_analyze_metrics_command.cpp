// `skinlab analyze metrics` as a user runs it: the real executable on EXR files and on a stimulus set.
#include "analysis/metrics/cvvdp.h"
#include "common/files.h"
#include "common/hash.h"
#include "synthetic_render.h"
#include "tests/common/temp_folder.h"

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
    // A passing test leaves nothing behind; a failing one keeps its files to look at.
    void TearDown() override { temp.keep = HasFailure(); }
    // `count` noisy copies of the reference (Gaussian noise of `sigma` per channel, RNG state firstState + seed) as
    // exr/seedN.exr: the comma-separated list --reference-seeds takes.
    std::string writeNoisySeeds(int count, std::uint64_t firstState, double sigma) {
        std::string seeds;
        for (int seed = 0; seed < count; ++seed) {
            testing::SyntheticRender noisy = reference;
            noisy.beauty = reference.beauty.clone();
            cv::Mat noise(noisy.beauty.size(), CV_32FC3);
            cv::theRNG().state = firstState + static_cast<std::uint64_t>(seed);
            cv::randn(noise, 0.0, sigma);
            noisy.beauty += noise;
            const std::string name = "exr/seed" + std::to_string(seed) + ".exr";
            testing::writeSyntheticExr(path(name), noisy);
            seeds += (seed ? "," : "") + path(name);
        }
        return seeds;
    }
    void SetUp() override {
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
    test_support::TempFolder temp;
    fs::path folder = temp.path();
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
    // ColorVideoVDP: 10 JOD for the identical render, less for the blurred one, its map written.
    EXPECT_EQ(json["comparisons"][0]["cvvdp_jod"], 10.0);
    EXPECT_LT(json["comparisons"][1]["cvvdp_jod"].get<double>(), 10.0);
    EXPECT_EQ(json["comparisons"][0]["image"]["cvvdp_map_mean"], 0.0);
    EXPECT_GT(halo["halo"]["cvvdp_map_mean"].get<double>(), halo["interior"]["cvvdp_map_mean"].get<double>());
    EXPECT_EQ(json["settings"]["cvvdp"]["display"], "standard_fhd");
    EXPECT_TRUE(fs::exists(path("out/heatmaps/halo.cvvdp.png")));
}

// --display picks a model; the custom options change it (same photometry, the 4K model's ppd: same JOD).
TEST_F(AnalyzeMetricsCommand, DisplayModelAndCustomDisplay) {
    testing::writeSyntheticExr(path("exr/reference.exr"), reference);
    testing::writeSyntheticExr(path("exr/halo.exr"), blurred);
    const std::string files = " --reference " + path("exr/reference.exr") + " " + path("exr/halo.exr");
    auto jodOf = [&](const std::string& options, const std::string& out) {
        CommandResult run = runSkinlab("analyze metrics" + files + " --no-heatmaps -o " + path(out) + options);
        EXPECT_EQ(run.exitCode, 0) << run.output;
        return nlohmann::json::parse(readFile(path(out + "/metrics.json")));
    };
    const auto fhd = jodOf("", "fhd");
    const auto uhd = jodOf(" --display standard_4k", "4k");
    const auto custom = jodOf(" --display-ppd 75.40244934516305", "custom");
    const double jodFhd = fhd["comparisons"][0]["cvvdp_jod"], jod4k = uhd["comparisons"][0]["cvvdp_jod"];
    EXPECT_GT(jod4k, jodFhd); // twice the pixels per degree: the blur is harder to see
    EXPECT_NEAR(custom["comparisons"][0]["cvvdp_jod"].get<double>(), jod4k, 1e-9);
    EXPECT_EQ(custom["settings"]["cvvdp"]["display"], "custom");
    const auto dim = jodOf(" --display-peak 20 --display-ambient 0", "dim");
    EXPECT_NE(dim["comparisons"][0]["cvvdp_jod"].get<double>(), jodFhd);
    EXPECT_EQ(dim["settings"]["cvvdp"]["peak_luminance"], 20.0);
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
    EXPECT_LT(json["comparisons"][0]["cvvdp_jod"].get<double>(), 10.0);
    EXPECT_TRUE(json["comparisons"][0]["cvvdp_heatmap"].is_null());
    EXPECT_FALSE(fs::exists(path("out/heatmaps")));
}

// A block of conditions from two renderers (skinlab's separable, EEVEE) gets one warning line; one renderer none.
TEST_F(AnalyzeMetricsCommand, WarnsWhenABlockMixesRenderers) {
    const auto runWith = [&](const std::string& secondMethod) {
        nlohmann::json manifest = {
            {"format", "skinlab-stimuli"}, {"version", 1}, {"set", "cli"}, {"stimuli", nlohmann::json::array()}};
        for (auto [id, method, isReference] :
             {std::tuple{"disc-reference", "reference", true}, std::tuple{"disc-separable", "separable", false},
              std::tuple{"disc-second", secondMethod.c_str(), false}}) {
            const std::string exr = std::string("exr/") + id + ".exr";
            testing::writeSyntheticExr(path(exr), isReference ? reference : blurred);
            manifest["stimuli"].push_back({{"id", id},
                                           {"files", {{"exr", exr}}},
                                           {"sha256", {{"exr", sha256File(path(exr))}}},
                                           {"factors", {{"method", method}}},
                                           {"resolved", {{"sss", {{"method", method}}}}},
                                           {"block", "builtin:disc/mid"},
                                           {"reference", isReference}});
        }
        writeFileAtomic(path("manifest.json"), manifest.dump(2));
        return runSkinlab("analyze metrics --stimuli " + folder.string() + " -o " + path("out") + " --no-heatmaps");
    };
    const CommandResult mixed = runWith("eevee");
    ASSERT_EQ(mixed.exitCode, 0) << mixed.output;
    EXPECT_NE(mixed.output.find("builtin:disc/mid: conditions of different renderers (skinlab, eevee) are compared "
                                "directly"),
              std::string::npos)
        << mixed.output;
    const CommandResult single = runWith("artistic");
    ASSERT_EQ(single.exitCode, 0) << single.output;
    EXPECT_EQ(single.output.find("different renderers"), std::string::npos) << single.output;
}

std::string displayList() {
    std::string list;
    for (const std::string& name : cvvdpDisplayNames()) list += (list.empty() ? "" : ", ") + name;
    return list;
}

// Bad input: exit code 2 and exactly one line naming the file and the channel, attribute or size at fault.
// --reference-seeds: the tests against several noisy copies of the truth; --compare-reference ranks them against a
// second truth. The halo render is worse than the exact one under both.
TEST_F(AnalyzeMetricsCommand, ScoresAgainstSeededTruthsAndComparesRankings) {
    const std::string seeds = writeNoisySeeds(4, 77, 0.03);
    testing::writeSyntheticExr(path("exr/reference.exr"), reference);
    testing::writeSyntheticExr(path("exr/halo.exr"), blurred);
    CommandResult run =
        runSkinlab("analyze metrics --reference-seeds " + seeds + " --compare-reference " + path("exr/reference.exr") +
                   " " + path("exr/halo.exr") + " " + path("exr/reference.exr") + " -o " + path("seeded"));
    ASSERT_EQ(run.exitCode, 0) << run.output;
    const auto json = nlohmann::json::parse(readFile(path("seeded/debiased.json")));
    ASSERT_EQ(json["seeds"].size(), 4u);
    ASSERT_EQ(json["tests"].size(), 2u);
    const auto& halo = json["tests"][0]["regions"]["halo"];
    const auto& exact = json["tests"][1]["regions"]["halo"];
    EXPECT_GT(halo["mse"]["value"].get<double>(), 0.0);
    EXPECT_NEAR(exact["mse"]["value"].get<double>(), 0.0, 3.0 * exact["mse"]["standard_error"].get<double>() + 1e-9);
    // One noisy seed alone adds its variance (0.03² in each channel, so in Y) to the exact render's error.
    EXPECT_GT(exact["plain_mse_one_seed"].get<double>(), 0.5 * 0.03 * 0.03);
    EXPECT_GT(halo["difference_from_compared"]["value"].get<double>(),
              1.96 * halo["difference_from_compared"]["standard_error"].get<double>());
    EXPECT_EQ(json["ranking_agreement"]["halo"]["tau_b"]["value"], 1.0);
    EXPECT_TRUE(fs::exists(path("seeded/debiased.csv")));

    // One seed, or seeds with --reference: one line, exit 2, nothing written.
    CommandResult one = runSkinlab("analyze metrics --reference-seeds " + path("exr/seed0.exr") + " " +
                                   path("exr/halo.exr") + " -o " + path("one"));
    EXPECT_EQ(one.exitCode, 2) << one.output;
    EXPECT_NE(one.output.find("--reference-seeds: needs at least two"), std::string::npos) << one.output;
    EXPECT_FALSE(fs::exists(path("one/debiased.json")));
    CommandResult both = runSkinlab("analyze metrics --reference " + path("exr/reference.exr") + " --reference-seeds " +
                                    seeds + " " + path("exr/halo.exr") + " -o " + path("both"));
    EXPECT_EQ(both.exitCode, 2) << both.output;
    EXPECT_NE(both.output.find("--reference: cannot be combined with --reference-seeds"), std::string::npos)
        << both.output;
    CommandResult compareOnly =
        runSkinlab("analyze metrics --reference " + path("exr/reference.exr") + " --compare-reference " +
                   path("exr/reference.exr") + " " + path("exr/halo.exr") + " -o " + path("compare"));
    EXPECT_EQ(compareOnly.exitCode, 2) << compareOnly.output;
    EXPECT_NE(compareOnly.output.find("--compare-reference: only with --reference-seeds"), std::string::npos)
        << compareOnly.output;
}

// --compare-metrics: the scores of `analyze metrics --reference` on the same files, each ranked against the seeded
// truth (table_score_agreement), and agreement.csv with every subset; a metrics.json without a test fails.
TEST_F(AnalyzeMetricsCommand, RanksTheTableScoresAgainstTheSeededTruth) {
    const std::string seeds = writeNoisySeeds(3, 91, 0.01);
    testing::writeSyntheticExr(path("exr/reference.exr"), reference);
    testing::writeSyntheticExr(path("exr/halo.exr"), blurred);
    const std::string tests = path("exr/halo.exr") + " " + path("exr/reference.exr");
    ASSERT_EQ(
        runSkinlab("analyze metrics --reference " + path("exr/reference.exr") + " " + tests + " -o " + path("table"))
            .exitCode,
        0);
    CommandResult run =
        runSkinlab("analyze metrics --reference-seeds " + seeds + " --compare-reference " + path("exr/reference.exr") +
                   " --compare-metrics " + path("table/metrics.json") + " " + tests + " -o " + path("seeded"));
    ASSERT_EQ(run.exitCode, 0) << run.output;
    const auto json = nlohmann::json::parse(readFile(path("seeded/debiased.json")));
    const auto& halo = json["table_score_agreement"]["halo_leak_energy"];
    EXPECT_EQ(halo["truth"]["quantity"], "Y");
    EXPECT_EQ(halo["conditions"], 2u);
    EXPECT_EQ(halo["tau_b"]["value"], 1.0);                               // the halo render is worse under both
    EXPECT_NEAR(halo["jackknife_t_quantile"].get<double>(), 4.303, 1e-3); // three seeds: t(0.975, 2)
    EXPECT_EQ(json["table_score_agreement"]["halo_excess"]["truth"]["quantity"], "Lab");
    EXPECT_TRUE(json["ranking_agreement_by_quantity"]["R"]["halo"].contains("competitive"));
    EXPECT_TRUE(json["tests"][0]["regions"]["halo"]["by_quantity"].contains("Lab"));
    const std::string csv = readFile(path("seeded/agreement.csv"));
    EXPECT_NE(csv.find("halo_leak_energy,halo,Y,mse,competitive,2,1,"), std::string::npos) << csv;

    CommandResult missing = runSkinlab("analyze metrics --reference-seeds " + seeds + " --compare-reference " +
                                       path("exr/reference.exr") + " --compare-metrics " + path("table/metrics.json") +
                                       " " + path("exr/seed0.exr") + " -o " + path("missing"));
    EXPECT_EQ(missing.exitCode, 2) << missing.output;
    EXPECT_NE(missing.output.find("metrics.json: has no comparison of"), std::string::npos) << missing.output;
    EXPECT_FALSE(fs::exists(path("missing/debiased.json")));
}

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
        {"--reference " + path("exr/reference.exr") + " " + path("exr/reference.exr") + " --display-ppd 0",
         "--display-ppd: 0 must be a positive number"},
        {"--reference " + path("exr/reference.exr") + " " + path("exr/reference.exr") + " --display-resolution 12x",
         "--display-resolution: \"12x\" must be WIDTHxHEIGHT in pixels, e.g. 1920x1080"},
        {"--reference " + path("exr/reference.exr") + " " + path("exr/reference.exr") + " --display-contrast 0.5",
         "--display-contrast: 0.5 must be a number >= 1"},
        {"--reference " + path("exr/reference.exr") + " " + path("exr/reference.exr") + " --display nope",
         "--display: \"nope\" is not one of " + displayList()},
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
