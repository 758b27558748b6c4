// runMetrics end to end on EXR files: the outputs, and bad input rejected word for word before anything is written.
#include "analysis/metrics/metrics_run.h"

#include "common/error.h"
#include "common/files.h"
#include "synthetic_render.h"
#include "tests/common/temp_folder.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

namespace skinlab::metrics {
namespace {
namespace fs = std::filesystem;
using testing::SyntheticRender;

class MetricsRun : public ::testing::Test {
protected:
    // A passing test leaves nothing behind; a failing one keeps its files to look at.
    void TearDown() override { temp.keep = HasFailure(); }
    void SetUp() override {
        testing::DiscScene scene;
        scene.size = 96;
        scene.stripeHalfWidth = 0.02;
        render = testing::renderDiscScene(scene);
        output = folder / "out";
    }
    fs::path write(const std::string& name, const SyntheticRender& r, const testing::WriteOptions& options = {}) {
        fs::path path = folder / name;
        testing::writeSyntheticExr(path, r, options);
        return path;
    }
    // Runs and returns the InputError message ("" if none was thrown).
    std::string failureOf(const fs::path& reference, const std::vector<fs::path>& tests,
                          MetricsRunOptions options = {}) {
        try {
            runMetrics(planFileComparisons(reference, tests), options, output);
        } catch (const InputError& e) {
            return e.what();
        }
        return "";
    }
    test_support::TempFolder temp;
    fs::path folder = temp.path();
    fs::path output;
    SyntheticRender render;
};

TEST_F(MetricsRun, WritesCsvJsonAndHeatmaps) {
    fs::path reference = write("ref.exr", render);
    SyntheticRender brighter = render;
    brighter.beauty = cv::Mat(render.beauty * 1.1); // a new buffer: `render` must stay unchanged
    fs::path same = write("same.exr", render);
    fs::path changed = write("brighter.exr", brighter);
    auto records = runMetrics(planFileComparisons(reference, {same, changed}), {}, output);
    ASSERT_EQ(records.size(), 2u);

    nlohmann::json json = nlohmann::json::parse(readFile(output / "metrics.json"));
    EXPECT_EQ(json["format"], "skinlab-metrics");
    EXPECT_EQ(json["version"], 1);
    ASSERT_EQ(json["comparisons"].size(), 2u);
    const auto& first = json["comparisons"][0];
    EXPECT_EQ(first["reference"]["name"], "ref");
    EXPECT_EQ(first["test"]["name"], "same");
    EXPECT_TRUE(first["image"]["psnr_db"].is_null()) << "identical: infinite PSNR is written as null";
    EXPECT_EQ(first["bands"]["halo"]["leak_energy"], 0.0);
    const auto& second = json["comparisons"][1];
    EXPECT_GT(second["skin"]["delta_e00_mean"].get<double>(), 0.5);
    EXPECT_GT(second["bands"]["halo"]["pixels"].get<int>(), 0);
    EXPECT_NEAR(second["support_radius_world"].get<double>(), 0.008, 1e-9); // 8 mm / 1000 mm per unit
    EXPECT_EQ(second["heatmap"], "heatmaps/brighter.png");

    std::string csv = readFile(output / "metrics.csv");
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3);
    EXPECT_EQ(csv.rfind("reference,test,block,width,height,", 0), 0u);
    EXPECT_NE(csv.find("\nref,same,,96,96,"), std::string::npos);
    EXPECT_NE(csv.find(",inf,"), std::string::npos) << "identical images: PSNR inf in the CSV";

    cv::Mat heatmap = cv::imread((output / "heatmaps/brighter.png").string(), cv::IMREAD_COLOR);
    ASSERT_FALSE(heatmap.empty());
    EXPECT_EQ(heatmap.cols, 96 + 170); // image + legend panel
    EXPECT_EQ(heatmap.rows, 260);      // the legend's minimum height
    // No temporary files left behind.
    for (const auto& entry : fs::recursive_directory_iterator(output))
        EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
}

TEST_F(MetricsRun, MissingFileIsNamed) {
    fs::path reference = write("ref.exr", render);
    EXPECT_EQ(failureOf(reference, {folder / "missing.exr"}), (folder / "missing.exr").string() + ": file not found");
    EXPECT_EQ(failureOf(folder / "nope.exr", {reference}), (folder / "nope.exr").string() + ": file not found");
}

TEST_F(MetricsRun, MissingChannelsAreNamed) {
    fs::path noDepth = write("no-depth.exr", render, {{"depth.Z"}, {}});
    fs::path noMask = write("no-mask.exr", render, {{"mask.Y"}, {}});
    fs::path noBlue = write("no-blue.exr", render, {{"B"}, {}});
    fs::path good = write("good.exr", render);
    EXPECT_EQ(failureOf(noDepth, {good}), noDepth.string() + ": depth.Z: channel is missing");
    EXPECT_EQ(failureOf(noMask, {good}), noMask.string() + ": mask.Y: channel is missing");
    EXPECT_EQ(failureOf(good, {noBlue}), noBlue.string() + ": B: channel is missing");
    // A test render needs only its beauty.
    EXPECT_EQ(failureOf(good, {noDepth, noMask}), "");
}

TEST_F(MetricsRun, MissingMetadataIsNamed) {
    fs::path good = write("good.exr", render);
    fs::path noFocal = write("no-f.exr", render, {{}, {"skinlab:f_px"}});
    fs::path noScale = write("no-scale.exr", render, {{}, {"skinlab:mm_per_unit"}});
    fs::path noRadius = write("no-radius.exr", render, {{}, {"skinlab:sss_radius_mm"}});
    EXPECT_EQ(failureOf(noFocal, {good}), noFocal.string() + ": skinlab:f_px: metadata attribute is missing");
    EXPECT_EQ(failureOf(noScale, {good}), noScale.string() + ": skinlab:mm_per_unit: metadata attribute is missing");
    EXPECT_EQ(failureOf(noRadius, {good}),
              noRadius.string() + ": skinlab:sss_radius_mm: metadata attribute is missing (or give --sss-radius-mm)");
    MetricsRunOptions withRadius;
    withRadius.metric.sssRadiusMillimetres = 6.0;
    EXPECT_EQ(failureOf(noRadius, {good}, withRadius), "");
}

TEST_F(MetricsRun, SizeMismatchIsNamed) {
    testing::DiscScene small;
    small.size = 64;
    fs::path reference = write("ref.exr", render);
    fs::path other = write("small.exr", testing::renderDiscScene(small));
    EXPECT_EQ(failureOf(reference, {other}),
              other.string() + ": size 64x64 differs from the reference " + reference.string() + " (96x96)");
}

TEST_F(MetricsRun, DifferentCameraIsNamed) {
    fs::path reference = write("ref.exr", render);
    SyntheticRender zoomed = render;
    zoomed.focalLengthPixels = 2 * render.focalLengthPixels;
    fs::path other = write("zoomed.exr", zoomed);
    // Values printed with 9 significant digits; the float32 metadata read back exactly.
    auto printed = [](float value) {
        std::ostringstream text;
        text.precision(9);
        text << static_cast<double>(value);
        return text.str();
    };
    EXPECT_EQ(failureOf(reference, {other}), other.string() + ": skinlab:f_px: " + printed(zoomed.focalLengthPixels) +
                                                 " differs from the reference's " + printed(render.focalLengthPixels) +
                                                 " (not the same camera)");
    EXPECT_FALSE(fs::exists(output)) << "checked before anything is written";
}

TEST_F(MetricsRun, NotAnImageIsNamed) {
    fs::path reference = write("ref.exr", render);
    fs::path text = folder / "text.exr";
    std::ofstream(text) << "not an image\n";
    std::string message = failureOf(reference, {text});
    EXPECT_EQ(message.rfind(text.string() + ": not a readable image (", 0), 0u) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << "one line";
}

// A failing run writes nothing, and a previous run's tables survive it.
TEST_F(MetricsRun, BadInputLeavesEarlierOutputsIntact) {
    fs::path reference = write("ref.exr", render);
    fs::path good = write("good.exr", render);
    runMetrics(planFileComparisons(reference, {good}), {}, output);
    std::string before = readFile(output / "metrics.json");
    fs::path noBlue = write("no-blue.exr", render, {{"B"}, {}});
    EXPECT_NE(failureOf(reference, {good, noBlue}), "");
    EXPECT_EQ(readFile(output / "metrics.json"), before);
    fs::path fresh = folder / "fresh";
    output = fresh;
    EXPECT_NE(failureOf(reference, {good, noBlue}), "");
    EXPECT_FALSE(fs::exists(fresh / "metrics.json"));
    EXPECT_FALSE(fs::exists(fresh / "heatmaps"));
}

TEST_F(MetricsRun, RepeatedTestNamesAreRejected) {
    fs::create_directories(folder / "a");
    fs::create_directories(folder / "b");
    fs::path reference = write("ref.exr", render);
    fs::path a = write("a/x.exr", render);
    fs::path b = write("b/x.exr", render);
    EXPECT_EQ(failureOf(reference, {a, b}), b.string() + ": test name 'x' repeats (" + a.string() +
                                                "); heat maps are named after the file stem, so rename one");
}

} // namespace
} // namespace skinlab::metrics

namespace skinlab::metrics {
namespace {
// A render without SSS (method "none") stores skinlab:sss_radius_mm = 0; as a test render its radius is never
// used, so it is compared like any other.
TEST(MetricsRunTestRender, ZeroRadiusOfATestRenderIsIgnored) {
    const test_support::TempFolder temp;
    const fs::path& folder = temp.path();
    testing::DiscScene scene;
    scene.size = 48;
    SyntheticRender reference = testing::renderDiscScene(scene);
    SyntheticRender none = reference;
    none.sssRadiusMillimetres = 0.0f;
    testing::writeSyntheticExr(folder / "ref.exr", reference);
    testing::writeSyntheticExr(folder / "none.exr", none);
    auto records = runMetrics(planFileComparisons(folder / "ref.exr", {folder / "none.exr"}), {}, folder / "out");
    ASSERT_EQ(records.size(), 1u);
    EXPECT_EQ(records[0].image.flipMean, 0.0);
}
} // namespace
} // namespace skinlab::metrics
