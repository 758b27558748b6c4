// The level search of `skinlab stimuli calibrate` on synthetic predictions with known answers (no rendering):
// increasing and decreasing differences, targets shared between probes, unreachable targets, the tolerance,
// whole-number parameters, steps and non-monotone predictions, and the bad arguments it names.
#include "common/error.h"
#include "stimuli/calibrate.h"

#include <cmath>
#include <gtest/gtest.h>
#include <map>

using skinlab::stimuli::LevelSearch;
using skinlab::stimuli::levelText;
using skinlab::stimuli::searchLevels;

namespace {

// A prediction that counts how often each value was asked for.
struct Counted {
    std::function<double(double)> difference; // 10 − JOD
    std::map<double, int> calls;
    std::function<double(double)> jod() {
        return [this](double v) {
            ++calls[v];
            return 10.0 - difference(v);
        };
    }
};

} // namespace

TEST(CalibrateSearch, IncreasingDifferenceFindsEachTargetWithinTheTolerance) {
    Counted f{[](double v) { return v * v; }}; // difference v²: target T at √T
    LevelSearch search{0.0, 4.0, 0.05};
    auto result = searchLevels(f.jod(), {0.5, 1.0, 2.0}, search);
    ASSERT_EQ(result.levels.size(), 3u);
    EXPECT_DOUBLE_EQ(result.differenceAtLo, 0.0);
    EXPECT_DOUBLE_EQ(result.differenceAtHi, 16.0);
    int renders = 0;
    for (const auto& level : result.levels) {
        EXPECT_TRUE(level.reached) << level.targetJod << ": " << level.note;
        EXPECT_LE(std::abs(level.achievedJod - level.targetJod), 0.05);
        EXPECT_DOUBLE_EQ(level.achievedJod, level.value * level.value);
        // |v² − T| ≤ 0.05 bounds |v − √T| by 0.05 / (2·√T) (and a bit)
        EXPECT_NEAR(level.value, std::sqrt(level.targetJod), 0.05 / std::sqrt(level.targetJod));
        renders += level.renders;
    }
    // Every value is predicted once; the per-target counts and the two ends add up to all predictions.
    for (const auto& [v, n] : f.calls) EXPECT_EQ(n, 1) << v;
    EXPECT_EQ(result.predictions, static_cast<int>(f.calls.size()));
    EXPECT_EQ(renders + 2, result.predictions);
    EXPECT_TRUE(result.warnings.empty());
}

TEST(CalibrateSearch, DecreasingDifference) {
    Counted f{[](double v) { return 4.0 - v; }}; // the reference is at the top of the range
    auto result = searchLevels(f.jod(), {1.0, 3.0}, LevelSearch{0.0, 4.0, 0.01});
    ASSERT_EQ(result.levels.size(), 2u);
    EXPECT_TRUE(result.levels[0].reached);
    EXPECT_NEAR(result.levels[0].value, 3.0, 0.01);
    EXPECT_TRUE(result.levels[1].reached);
    EXPECT_NEAR(result.levels[1].value, 1.0, 0.01);
}

TEST(CalibrateSearch, TargetOutsideTheEndsIsUnreachableWithoutProbing) {
    Counted f{[](double v) { return v; }};
    auto result = searchLevels(f.jod(), {2.0, 0.5}, LevelSearch{0.0, 1.0, 0.05});
    const auto& far = result.levels[0];
    EXPECT_FALSE(far.reached);
    EXPECT_NE(far.note.find("unreachable"), std::string::npos) << far.note;
    EXPECT_NE(far.note.find("at 1"), std::string::npos) << far.note; // names the ends
    EXPECT_DOUBLE_EQ(far.value, 1.0);                                // the closest end
    EXPECT_EQ(far.renders, 0);
    EXPECT_TRUE(result.levels[1].reached); // the other target is still searched
    EXPECT_NEAR(result.levels[1].value, 0.5, 0.05);
}

TEST(CalibrateSearch, AnEndWithinTheToleranceIsTaken) {
    Counted f{[](double v) { return v; }};
    auto result = searchLevels(f.jod(), {1.03}, LevelSearch{0.0, 1.0, 0.05});
    EXPECT_TRUE(result.levels[0].reached);
    EXPECT_DOUBLE_EQ(result.levels[0].value, 1.0);
    EXPECT_EQ(result.predictions, 2);
}

TEST(CalibrateSearch, TighterToleranceTakesMoreProbesAndStaysWithinIt) {
    auto probesFor = [](double tolerance) {
        Counted f{[](double v) { return 3.0 * std::log1p(v); }};
        auto result = searchLevels(f.jod(), {1.0}, LevelSearch{0.0, 10.0, tolerance});
        EXPECT_TRUE(result.levels[0].reached) << tolerance;
        EXPECT_LE(std::abs(result.levels[0].achievedJod - 1.0), tolerance);
        EXPECT_NEAR(result.levels[0].value, std::expm1(1.0 / 3.0), 2.0 * tolerance);
        return result.levels[0].renders;
    };
    const int coarse = probesFor(0.2), fine = probesFor(0.001);
    EXPECT_LT(coarse, fine);
    EXPECT_GE(coarse, 1);
}

TEST(CalibrateSearch, GivesUpAfterMaxProbes) {
    Counted f{[](double v) { return v; }};
    LevelSearch search{0.0, 1.0, 1e-9};
    search.maxProbes = 5;
    auto result = searchLevels(f.jod(), {0.3}, search);
    EXPECT_FALSE(result.levels[0].reached);
    EXPECT_EQ(result.levels[0].renders, 5);
    EXPECT_NE(result.levels[0].note.find("after 5 probes"), std::string::npos) << result.levels[0].note;
    EXPECT_NEAR(result.levels[0].value, 0.3, 1.0 / 32.0);
}

TEST(CalibrateSearch, WholeNumberParameterProbesIntegersAndReportsTheJump) {
    Counted f{[](double v) { return 0.5 * v; }};
    LevelSearch search{0.0, 20.0, 0.05};
    search.integral = true;
    auto result = searchLevels(f.jod(), {3.0, 1.25}, search);
    EXPECT_TRUE(result.levels[0].reached);
    EXPECT_DOUBLE_EQ(result.levels[0].value, 6.0);
    EXPECT_FALSE(result.levels[1].reached); // 1.25 lies between 2 (1.0) and 3 (1.5)
    EXPECT_NE(result.levels[1].note.find("whole numbers"), std::string::npos) << result.levels[1].note;
    for (const auto& [v, n] : f.calls) EXPECT_EQ(v, std::round(v));
}

TEST(CalibrateSearch, StepIsReportedNotLoopedOn) {
    Counted f{[](double v) { return v < 0.3 ? 0.0 : 2.0; }};
    LevelSearch search{0.0, 1.0, 0.05};
    search.maxProbes = 60;
    auto result = searchLevels(f.jod(), {1.2}, search);
    EXPECT_FALSE(result.levels[0].reached);
    EXPECT_NE(result.levels[0].note.find("jumps"), std::string::npos) << result.levels[0].note;
    EXPECT_LT(result.predictions, 50);
    EXPECT_NEAR(result.levels[0].value, 0.3, 1e-6);
}

TEST(CalibrateSearch, NonMonotonePredictionIsWarnedAbout) {
    // A bump at the middle of the range, above both ends: the first probe leaves the bracket.
    Counted f{[](double v) { return v + 3.0 * std::exp(-std::pow((v - 0.5) / 0.05, 2.0)); }};
    auto result = searchLevels(f.jod(), {0.8}, LevelSearch{0.0, 1.0, 0.05});
    ASSERT_FALSE(result.warnings.empty());
    EXPECT_NE(result.warnings[0].find("not monotone"), std::string::npos) << result.warnings[0];
}

TEST(CalibrateSearch, ParameterWithoutEffectIsWarnedAbout) {
    Counted f{[](double) { return 0.01; }};
    auto result = searchLevels(f.jod(), {1.0}, LevelSearch{0.0, 1.0, 0.05});
    EXPECT_FALSE(result.levels[0].reached);
    ASSERT_FALSE(result.warnings.empty());
    EXPECT_NE(result.warnings[0].find("barely changes"), std::string::npos) << result.warnings[0];
}

TEST(CalibrateSearch, BadArgumentsNameTheirOption) {
    auto jod = [](double v) { return 10.0 - v; };
    auto message = [&](const std::vector<double>& targets, LevelSearch search) {
        try {
            searchLevels(jod, targets, search);
        } catch (const skinlab::InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(message({1.0}, LevelSearch{2.0, 1.0, 0.05}).find("--range"), std::string::npos);
    EXPECT_NE(message({1.0}, LevelSearch{1.0, 1.0, 0.05}).find("--range"), std::string::npos);
    EXPECT_NE(message({1.0}, LevelSearch{0.0, 1.0, 0.0}).find("--tolerance"), std::string::npos);
    EXPECT_NE(message({0.0}, LevelSearch{0.0, 1.0, 0.05}).find("--target-jod"), std::string::npos);
    EXPECT_NE(message({}, LevelSearch{0.0, 1.0, 0.05}).find("--target-jod"), std::string::npos);
    EXPECT_NE(message({0.05}, LevelSearch{0.0, 1.0, 0.05}).find("--target-jod"), std::string::npos);
    LevelSearch integral{0.2, 0.8, 0.05};
    integral.integral = true;
    EXPECT_NE(message({1.0}, integral).find("whole numbers"), std::string::npos);
}

TEST(CalibrateSearch, LevelTextIsTomlThatReadsBackExactly) {
    EXPECT_EQ(levelText(2.0, false), "2.0");
    EXPECT_EQ(levelText(0.8125, false), "0.8125");
    EXPECT_EQ(levelText(0.1, false), "0.1");
    EXPECT_EQ(levelText(3.0, true), "3");
    const double odd = 1.0 / 3.0;
    EXPECT_EQ(std::stod(levelText(odd, false)), odd);
}
