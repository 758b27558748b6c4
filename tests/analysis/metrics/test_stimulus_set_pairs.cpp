// Which renders a stimulus set compares with which reference (manifest.json, contract 2).
#include "analysis/metrics/stimulus_set_pairs.h"

#include "common/error.h"
#include "common/files.h"
#include "common/hash.h"
#include "synthetic_render.h"
#include "tests/common/temp_folder.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace skinlab::metrics {
namespace {
namespace fs = std::filesystem;

class StimulusSetPairs : public ::testing::Test {
protected:
    // A passing test leaves nothing behind; a failing one keeps its files to look at.
    void TearDown() override { temp.keep = HasFailure(); }
    void SetUp() override {
        fs::create_directories(folder / "exr");
        testing::DiscScene scene;
        scene.size = 32;
        testing::SyntheticRender render = testing::renderDiscScene(scene);
        for (const char* id : {"disc-reference", "disc-separable", "disc-gaussian", "head-separable"})
            testing::writeSyntheticExr(folder / "exr" / (std::string(id) + ".exr"), render);
        manifest = {
            {"format", "skinlab-stimuli"}, {"version", 1}, {"set", "test"}, {"stimuli", nlohmann::json::array()}};
        addStimulus("disc-reference", "builtin:disc/mid", "reference", true);
        addStimulus("disc-separable", "builtin:disc/mid", "separable", false);
        addStimulus("disc-gaussian", "builtin:disc/mid", "gaussian-sum", false);
        addStimulus("head-separable", "builtin:head/close", "separable", false);
    }
    void addStimulus(const std::string& id, const std::string& block, const std::string& method, bool reference) {
        std::string exr = "exr/" + id + ".exr";
        manifest["stimuli"].push_back({{"id", id},
                                       {"files", {{"exr", exr}, {"png", "png/" + id + ".png"}}},
                                       {"sha256", {{"exr", sha256File(folder / exr)}, {"png", "not-built"}}},
                                       {"factors", {{"method", method}}},
                                       {"block", block},
                                       {"reference", reference},
                                       {"width", 32},
                                       {"height", 32}});
    }
    ComparisonPlan plan(const std::optional<std::string>& reference = std::nullopt) {
        writeFileAtomic(folder / "manifest.json", manifest.dump());
        return planStimulusSetComparisons(folder, reference);
    }
    std::string failureOf(const std::optional<std::string>& reference = std::nullopt) {
        try {
            plan(reference);
        } catch (const InputError& e) {
            return e.what();
        }
        return "";
    }
    test_support::TempFolder temp;
    fs::path folder = temp.path();
    nlohmann::json manifest;
};

TEST_F(StimulusSetPairs, EachBlockIsComparedWithItsReference) {
    ComparisonPlan result = plan();
    ASSERT_EQ(result.jobs.size(), 2u);
    EXPECT_EQ(result.jobs[0].testName, "disc-separable");
    EXPECT_EQ(result.jobs[1].testName, "disc-gaussian");
    for (const auto& job : result.jobs) {
        EXPECT_EQ(job.referenceName, "disc-reference");
        EXPECT_EQ(job.referencePath, folder / "exr/disc-reference.exr");
        EXPECT_EQ(job.block, "builtin:disc/mid");
    }
    EXPECT_EQ(result.jobs[1].factors["method"], "gaussian-sum");
    EXPECT_EQ(result.blocksWithoutReference, std::vector<std::string>{"builtin:head/close"});
}

TEST_F(StimulusSetPairs, ReferenceIdChoosesTheReferenceOfItsBlock) {
    ComparisonPlan result = plan("disc-separable");
    ASSERT_EQ(result.jobs.size(), 2u);
    EXPECT_EQ(result.jobs[0].referenceName, "disc-separable");
    EXPECT_EQ(result.jobs[0].testName, "disc-reference");
    EXPECT_EQ(result.jobs[1].testName, "disc-gaussian");
    EXPECT_EQ(failureOf("nothing"), "--reference: no stimulus 'nothing' in " + (folder / "manifest.json").string());
}

TEST_F(StimulusSetPairs, ErrorsNameTheManifestAndTheKey) {
    const std::string file = (folder / "manifest.json").string();
    for (auto& stimulus : manifest["stimuli"]) stimulus["reference"] = false;
    EXPECT_EQ(failureOf(), file + ": no stimulus has \"reference\": true; name one with --reference ID");
    manifest["stimuli"][1]["reference"] = true;
    manifest["stimuli"][2]["reference"] = true;
    EXPECT_EQ(failureOf(), file + ": block 'builtin:disc/mid' has two reference stimuli ('disc-separable' and "
                                  "'disc-gaussian'); pick one with --reference ID");
    manifest["stimuli"][2]["reference"] = false;
    manifest["stimuli"][3]["files"].erase("exr");
    EXPECT_EQ(failureOf(), file + ": stimuli[3].files.exr: missing (image metrics read the renders)");
    manifest["format"] = "something-else";
    EXPECT_EQ(failureOf(), file + ": format: expected \"skinlab-stimuli\"");
    fs::remove(folder / "manifest.json");
    try {
        planStimulusSetComparisons(folder, std::nullopt);
        FAIL() << "no manifest";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()), file + ": no manifest.json in the stimulus folder");
    }
}

// A render changed after the set was built is not measured silently.
TEST_F(StimulusSetPairs, ChangedRenderIsRejectedByItsHash) {
    plan();
    testing::DiscScene other;
    other.size = 32;
    other.discRadius = 0.05;
    testing::writeSyntheticExr(folder / "exr/disc-gaussian.exr", testing::renderDiscScene(other));
    EXPECT_EQ(failureOf(), (folder / "exr/disc-gaussian.exr").string() + ": sha256 does not match " +
                               (folder / "manifest.json").string() + " (the file changed after the set was built)");
}

} // namespace
} // namespace skinlab::metrics
