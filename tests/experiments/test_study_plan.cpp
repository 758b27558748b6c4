// The power planner of `skinlab study plan` on designs with known answers: a large predicted difference is resolved
// by few observers, no difference is (almost) never resolved, and power grows with the number of observers.
#include "experiments/study_plan.h"

#include "common/error.h"
#include "common/files.h"
#include "experiments/study_creation.h"
#include "experiments/study_store.h"
#include "stimulus_set_fixture.h"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>
#include <regex>

using namespace skinlab::experiments;

namespace {

StudyDefinition threeConditions(int repetitions) {
    StudyDefinition definition;
    definition.design.repetitions = repetitions;
    definition.design.practiceTrials = 0;
    definition.design.blankCatchTrials = 0;
    StudyBlock block;
    block.name = "scene";
    block.conditions = {"a", "b", "c"};
    block.pairs = {{0, 1}, {0, 2}, {1, 2}};
    definition.blocks.push_back(block);
    return definition;
}

} // namespace

TEST(StudyPlan, PowerFollowsThePredictedDifferences) {
    SimulationTruth truth;
    // a and b 3 JOD apart (P = 0.98 per trial), b and c equal.
    truth.byCondition = {{"a", 3.0}, {"b", 0.0}, {"c", 0.0}};
    PlanOptions options;
    options.observerCounts = {5, 20, 80};
    options.simulations = 200;
    const StudyPlan plan = planStudy(threeConditions(2), truth, options);
    ASSERT_EQ(plan.blocks.size(), 1u);
    const PlannedBlock& block = plan.blocks[0];
    ASSERT_EQ(block.neighbours.size(), 2u);
    EXPECT_EQ(block.neighbours[0].better, "a");
    EXPECT_NEAR(block.neighbours[0].difference, 3.0, 1e-12);
    // 3 JOD: resolved in nearly every simulated study already with 5 observers.
    EXPECT_GE(block.neighbours[0].power[0], 0.9);
    // No difference: significant in the (predicted) direction at most about α/2 of the time, at any count.
    for (double p : block.neighbours[1].power) EXPECT_LE(p, 0.06);
    EXPECT_EQ(block.observersNeeded, -1) << "an equal pair can never reach power 0.8";
    EXPECT_EQ(plan.trialsPerObserver, 6);
    // The text says which pair keeps the block from being resolved, and how many pairs a study of each size should
    // still find significant (here the 3 JOD pair: about one), so that an outcome with significant pairs reads as
    // the plan foresaw it rather than against it.
    const std::string text = planText(plan);
    EXPECT_NE(text.find("not every neighbouring pair reaches power >= 0.8 by 80 observers: the closest, "),
              std::string::npos)
        << text;
    EXPECT_NE(text.find("(0.000 JOD), is too small for this design; pairs further apart can still come out"),
              std::string::npos)
        << text;
    EXPECT_EQ(text.find("the predicted differences are too small"), std::string::npos) << text;
    std::smatch expected;
    ASSERT_TRUE(std::regex_search(text, expected,
                                  std::regex("significant neighbouring pairs to expect \\(of 2\\): ([0-9.]+) at 5, "
                                             "[0-9.]+ at 20, [0-9.]+ at 80 observers\n")))
        << text;
    EXPECT_GE(std::stod(expected[1].str()), 0.9);
    EXPECT_LE(std::stod(expected[1].str()), 1.1);
}

TEST(StudyPlan, PowerGrowsWithObservers) {
    SimulationTruth truth;
    truth.byCondition = {{"a", 1.0}, {"b", 0.5}, {"c", 0.0}};
    PlanOptions options;
    options.observerCounts = {5, 20, 80};
    options.simulations = 300;
    const StudyPlan plan = planStudy(threeConditions(1), truth, options);
    const PlannedBlock& block = plan.blocks[0];
    for (const PlannedPair& pair : block.neighbours) {
        EXPECT_LT(pair.power[0], pair.power[1]);
        EXPECT_LT(pair.power[1], pair.power[2]);
    }
    // 0.5 JOD neighbours with 80 observers answering each pair once: resolved with power ≥ 0.8.
    EXPECT_EQ(block.observersNeeded, 80);
    EXPECT_NE(planText(plan).find("needs 80 observers"), std::string::npos) << planText(plan);
}

// `--truth predicted` reads each stimulus's predicted JOD from the manifest stored in the study, per block; a set
// built without predictions is refused, naming the stimulus.
TEST(StudyPlan, TruthFromThePredictionsInTheManifest) {
    using namespace skinlab::experiments::test_support;
    TempFolder folder("plan-truth");
    const std::filesystem::path stimuli = folder.path() / "stimuli";
    writeStimulusSet(stimuli);
    const std::filesystem::path design = writeText(folder.path(), "design.toml", "title = \"t\"\nseed = 3\n");
    // First without predictions.
    createStudy(stimuli, design, {}, folder.path() / "plain.db");
    {
        StudyStore store(folder.path() / "plain.db");
        try {
            truthFromPredictions(store);
            ADD_FAILURE() << "a set without predictions was accepted";
        } catch (const skinlab::InputError& e) {
            EXPECT_NE(std::string(e.what()).find("has no predicted JOD in the manifest"), std::string::npos)
                << e.what();
        }
    }
    // Then with them: JOD 9 + 0.1 × the method's index, different in each block.
    nlohmann::json manifest = nlohmann::json::parse(skinlab::readFile(stimuli / "manifest.json"));
    int k = 0;
    for (nlohmann::json& s : manifest["stimuli"])
        if (!s.value("reference", false)) s["predicted"] = {{"jod", 9.0 + 0.1 * k++}, {"display", "standard_fhd"}};
    skinlab::writeFileAtomic(stimuli / "manifest.json", manifest.dump(2));
    createStudy(stimuli, design, {}, folder.path() / "predicted.db");
    StudyStore store(folder.path() / "predicted.db");
    const SimulationTruth truth = truthFromPredictions(store);
    k = 0;
    for (const nlohmann::json& s : manifest["stimuli"])
        EXPECT_DOUBLE_EQ(truth.quality(s["block"].get<std::string>(), s["factors"]["method"].get<std::string>()),
                         s.value("reference", false) ? 10.0 : 9.0 + 0.1 * k++);
    // The planner takes it as any truth.
    PlanOptions options;
    options.observerCounts = {5};
    options.simulations = 20;
    EXPECT_EQ(planStudy(store.definition(), truth, options).blocks.size(), store.definition().blocks.size());
}
