// The power planner of `skinlab study plan` on designs with known answers: a large predicted difference is resolved
// by few observers, no difference is (almost) never resolved, and power grows with the number of observers.
#include "experiments/study_plan.h"

#include <gtest/gtest.h>

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
