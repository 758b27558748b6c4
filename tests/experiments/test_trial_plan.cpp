// Unit tests of study designs: parsing, resolution against a manifest, and per-participant trial plans
// (balance of sides, reproducibility from the seed, practice and catch placement).
#include "common/error.h"
#include "experiments/study_definition.h"
#include "experiments/trial_plan.h"
#include "stimulus_set_fixture.h"

#include <gtest/gtest.h>
#include <map>
#include <set>

using namespace skinlab::experiments;
using skinlab::experiments::test_support::TempFolder;

namespace {

StudyDefinition makeStudy(const std::string& designToml, const test_support::StimulusSetSpec& spec = {}) {
    TempFolder folder("plan");
    test_support::writeStimulusSet(folder.path(), spec);
    const StimulusManifest manifest = readStimulusManifest(folder.path());
    return resolveStudy(parseStudyDesign(designToml, "D.toml"), manifest);
}

std::string pairKey(const PlannedTrial& t) { return t.block + "|" + t.conditionA + "|" + t.conditionB; }

std::string expectInputError(const std::string& designToml) {
    try {
        makeStudy(designToml);
    } catch (const skinlab::InputError& e) {
        return e.what();
    }
    return "(no error)";
}

} // namespace

TEST(TrialPlan, ResolvesBlocksConditionsAndPairs) {
    const StudyDefinition study = makeStudy("seed = 7\n");
    ASSERT_EQ(study.blocks.size(), 2u);
    // Without reference.show the reference stimulus is an ordinary condition: 4 conditions, 6 pairs per block.
    EXPECT_EQ(study.blocks[0].conditions.size(), 4u);
    EXPECT_EQ(study.blocks[0].pairs.size(), 6u);
    EXPECT_EQ(study.testTrialCount(), 12);
    EXPECT_EQ(study.repeatTrialCount(), 12); // repetitions = 2 by default

    const StudyDefinition withReference = makeStudy("[reference]\nshow = true\n");
    EXPECT_EQ(withReference.blocks[0].conditions.size(), 3u);
    EXPECT_EQ(withReference.blocks[0].pairs.size(), 3u);
    ASSERT_GE(withReference.blocks[0].referenceStimulus, 0);
    EXPECT_EQ(withReference.stimuli[static_cast<std::size_t>(withReference.blocks[0].referenceStimulus)].id,
              "0-reference");

    const StudyDefinition listed = makeStudy("pairs = [[\"separable\", \"artistic\"]]\nblocks = [\"scene:b/close\"]\n");
    ASSERT_EQ(listed.blocks.size(), 1u);
    EXPECT_EQ(listed.blocks[0].name, "scene:b/close");
    ASSERT_EQ(listed.blocks[0].pairs.size(), 1u);
}

TEST(TrialPlan, SameSeedSamePlanOtherParticipantOtherOrder) {
    const StudyDefinition study = makeStudy("seed = 11\nrepetitions = 2\n");
    const auto seed3 = participantSeed(study.design.seed, 3);
    EXPECT_EQ(seed3, participantSeed(11, 3));
    EXPECT_NE(seed3, participantSeed(11, 4));
    EXPECT_NE(seed3, participantSeed(12, 3));
    const auto a = planTrials(study, 3, seed3);
    const auto b = planTrials(study, 3, seed3);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(pairKey(a[i]), pairKey(b[i])) << "position " << i;
        EXPECT_EQ(a[i].aOnLeft, b[i].aOnLeft) << "position " << i;
        EXPECT_EQ(a[i].kind, b[i].kind) << "position " << i;
    }
    const auto c = planTrials(study, 4, participantSeed(study.design.seed, 4));
    int differences = 0;
    for (std::size_t i = 0; i < std::min(a.size(), c.size()); ++i)
        differences += pairKey(a[i]) != pairKey(c[i]) ? 1 : 0;
    EXPECT_GT(differences, static_cast<int>(a.size()) / 2) << "orders of two participants should differ";
}

TEST(TrialPlan, EvenRepetitionsBalanceSidesWithinEachParticipant) {
    const StudyDefinition study = makeStudy("seed = 5\nrepetitions = 4\n");
    for (int participant = 0; participant < 5; ++participant) {
        const auto plan = planTrials(study, participant, participantSeed(study.design.seed, participant));
        std::map<std::string, int> aLeft, total;
        std::map<std::string, int> conditionLeft, conditionRight;
        int tests = 0, repeats = 0;
        for (const PlannedTrial& t : plan) {
            if (t.kind != TrialKind::test && t.kind != TrialKind::repeat) continue;
            tests += t.kind == TrialKind::test ? 1 : 0;
            repeats += t.kind == TrialKind::repeat ? 1 : 0;
            aLeft[pairKey(t)] += t.aOnLeft ? 1 : 0;
            total[pairKey(t)] += 1;
            conditionLeft[t.block + t.conditionA] += t.aOnLeft ? 1 : 0;
            conditionRight[t.block + t.conditionA] += t.aOnLeft ? 0 : 1;
            conditionLeft[t.block + t.conditionB] += t.aOnLeft ? 0 : 1;
            conditionRight[t.block + t.conditionB] += t.aOnLeft ? 1 : 0;
        }
        EXPECT_EQ(tests, 12);
        EXPECT_EQ(repeats, 36);
        for (const auto& [key, n] : total) {
            EXPECT_EQ(n, 4) << key;
            EXPECT_EQ(aLeft[key], 2) << key << ": both orders, equally often";
        }
        for (const auto& [key, n] : conditionLeft) EXPECT_EQ(n, conditionRight[key]) << key;
    }
}

TEST(TrialPlan, OddRepetitionsBalanceSidesAcrossParticipantPairs) {
    const StudyDefinition study = makeStudy("seed = 9\nrepetitions = 1\n");
    const auto first = planTrials(study, 0, participantSeed(study.design.seed, 0));
    const auto second = planTrials(study, 1, participantSeed(study.design.seed, 1));
    std::map<std::string, bool> sideOfFirst;
    for (const PlannedTrial& t : first)
        if (t.kind == TrialKind::test) sideOfFirst[pairKey(t)] = t.aOnLeft;
    ASSERT_EQ(sideOfFirst.size(), 12u);
    int checked = 0;
    for (const PlannedTrial& t : second)
        if (t.kind == TrialKind::test) {
            EXPECT_NE(t.aOnLeft, sideOfFirst.at(pairKey(t))) << pairKey(t) << ": participant 1 mirrors participant 0";
            ++checked;
        }
    EXPECT_EQ(checked, 12);
    // And the first-showing sides are not all the same (they come from the seed).
    int left = 0;
    for (const auto& [key, isLeft] : sideOfFirst) left += isLeft ? 1 : 0;
    EXPECT_GT(left, 0);
    EXPECT_LT(left, 12);
}

TEST(TrialPlan, PracticeFirstCatchSpreadAndNoPairTwiceInARow) {
    const StudyDefinition study = makeStudy(
        "seed = 3\nrepetitions = 2\n[practice]\ntrials = 3\n[catch]\nblank = 4\n"
        "[[catch.pairs]]\nfirst = \"0-reference\"\nsecond = \"0-artistic\"\nexpected = \"0-reference\"\nrepeat = 2\n");
    for (int participant = 0; participant < 6; ++participant) {
        const auto plan = planTrials(study, participant, participantSeed(study.design.seed, participant));
        ASSERT_EQ(plan.size(), 3u + 24u + 6u);
        for (int i = 0; i < 3; ++i) EXPECT_EQ(plan[static_cast<std::size_t>(i)].kind, TrialKind::practice) << i;
        EXPECT_NE(plan[3].kind, TrialKind::catchTrial) << "a catch trial never comes first";
        // Catch c lies in segment c of the 24 test/repeat trials: after at least max(1, c*24/6) and at most
        // (c+1)*24/6 of them.
        int mainSeen = 0, catchIndex = 0, correctLeft = 0, blank = 0, declared = 0;
        for (std::size_t i = 3; i < plan.size(); ++i) {
            const PlannedTrial& t = plan[i];
            EXPECT_NE(t.kind, TrialKind::practice);
            if (t.kind != TrialKind::catchTrial) {
                ++mainSeen;
                continue;
            }
            EXPECT_GE(mainSeen, std::max(1, catchIndex * 24 / 6)) << "catch " << catchIndex;
            EXPECT_LE(mainSeen, (catchIndex + 1) * 24 / 6) << "catch " << catchIndex;
            ++catchIndex;
            ASSERT_TRUE(t.expected == 'A' || t.expected == 'B');
            correctLeft += ((t.expected == 'A') == t.aOnLeft) ? 1 : 0;
            if (t.stimulusB == kBlankStimulus) {
                ++blank;
                EXPECT_EQ(t.expected, 'A');
                EXPECT_EQ(t.conditionB, "blank");
            } else {
                ++declared;
                EXPECT_EQ(study.stimuli[static_cast<std::size_t>(t.stimulusA)].id, "0-reference");
                EXPECT_EQ(t.expected, 'A');
            }
        }
        EXPECT_EQ(catchIndex, 6);
        EXPECT_EQ(blank, 4);
        EXPECT_EQ(declared, 2);
        EXPECT_EQ(correctLeft, 3) << "the right answer is left in half of the catch trials";
        for (std::size_t i = 1; i < plan.size(); ++i)
            if ((plan[i].kind == TrialKind::test || plan[i].kind == TrialKind::repeat) &&
                (plan[i - 1].kind == TrialKind::test || plan[i - 1].kind == TrialKind::repeat)) {
                EXPECT_NE(pairKey(plan[i]), pairKey(plan[i - 1])) << "same pair twice in a row at " << i;
            }
    }
}

TEST(TrialPlan, GroupedBlocksStayTogether) {
    const StudyDefinition study =
        makeStudy("seed = 2\nblock_order = \"grouped\"\n[catch]\nblank = 0\n[practice]\ntrials = 0\n");
    const auto plan = planTrials(study, 0, participantSeed(2, 0));
    int switches = 0;
    for (std::size_t i = 1; i < plan.size(); ++i) switches += plan[i].block != plan[i - 1].block ? 1 : 0;
    EXPECT_EQ(switches, 1);
}

TEST(TrialPlan, DesignErrorsNameFileKeyAndValue) {
    EXPECT_EQ(expectInputError("repetitions = 0\n"), "D.toml: repetitions: 0 is out of range [1, 100]");
    EXPECT_EQ(expectInputError("repetitons = 2\n"), "D.toml: repetitons: unknown key (did you mean repetitions?)");
    EXPECT_EQ(expectInputError("block_order = \"random\"\n"),
              "D.toml: block_order: 'random' is not one of: interleaved, grouped");
    EXPECT_EQ(
        expectInputError("conditions = [\"separabel\", \"artistic\"]\n"),
        "D.toml: conditions: \"separabel\" is not a level of factor \"method\" (levels: reference-like, separable, "
        "artistic, reference)");
    EXPECT_EQ(expectInputError("pairs = [[\"separable\", \"separable\"]]\n"),
              "D.toml: pairs[0]: a condition cannot be compared with itself (\"separable\")");
    EXPECT_EQ(expectInputError("pairs = \"some\"\n"),
              "D.toml: pairs: expected \"all\", \"active\" or an array of [A, B] condition pairs, got \"some\"");
    EXPECT_EQ(expectInputError("blocks = [\"scene:c\"]\n"),
              "D.toml: blocks: \"scene:c\" is not a block of the stimulus set (blocks: scene:a/mid, scene:b/close)");
    EXPECT_EQ(
        expectInputError("condition_factor = \"scene\"\n"),
        "D.toml: condition_factor: block \"scene:a/mid\" has two stimuli with scene=scene:a/mid (\"0-reference-like\", "
        "\"0-separable\"); choose a factor that tells them apart, or split blocks");
    EXPECT_EQ(
        expectInputError("[[catch.pairs]]\nfirst = \"0-separable\"\nsecond = \"0-nope\"\nexpected = \"0-separable\"\n"),
        "D.toml: catch.pairs[0].second: no stimulus with id \"0-nope\"");
    EXPECT_EQ(expectInputError("[[catch.pairs]]\nfirst = \"0-separable\"\nsecond = \"0-artistic\"\nexpected = \"x\"\n"),
              "D.toml: catch.pairs[0].expected: must be the first or the second stimulus id, got \"x\"");
}

TEST(TrialPlan, DefinitionRoundTripsThroughJson) {
    const StudyDefinition study = makeStudy("seed = 4\n[reference]\nshow = true\n[catch]\nblank = 1\n");
    const StudyDefinition copy = StudyDefinition::fromJson(study.toJson());
    EXPECT_EQ(copy.toJson(), study.toJson());
    const auto a = planTrials(study, 2, 99);
    const auto b = planTrials(copy, 2, 99);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(pairKey(a[i]), pairKey(b[i]));
}
