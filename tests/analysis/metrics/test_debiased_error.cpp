// Scoring against several path-traced seeds: the debiased squared error has no noise bias, its jackknife error
// covers the truth, paired differences and rankings follow the noise-free image (docs/metrics.md).
#include "analysis/metrics/debiased_error.h"
#include "analysis/metrics/metrics_run.h"
#include "analysis/metrics/seed_mean.h"
#include "common/error.h"
#include "common/files.h"
#include "synthetic_render.h"
#include "tests/common/temp_folder.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

namespace skinlab::metrics {
namespace {
namespace fs = std::filesystem;

class DebiasedError : public ::testing::Test {
protected:
    void SetUp() override {
        scene.size = 96;
        scene.farPlaneIsSkin = false;
        truth = testing::renderDiscScene(scene);
    }

    // The noise-free render plus independent Gaussian noise of standard deviation `sigma` per pixel and channel,
    // with the metadata of a path-traced render of seed `seed` (`scene` stands for the rest of skinlab:resolved).
    fs::path writeSeed(int seed, double sigma, int replicate = 0, const std::string& scene = "head") {
        testing::SyntheticRender noisy = truth;
        noisy.beauty = truth.beauty.clone();
        std::mt19937 random(static_cast<unsigned>(1000 * replicate + seed + 1));
        std::normal_distribution<float> noise(0.0f, static_cast<float>(sigma));
        for (int y = 0; y < noisy.height; ++y)
            for (int x = 0; x < noisy.width; ++x) {
                // The same noise on R, G and B: the luminance noise is sigma.
                const float n = noise(random);
                auto& pixel = noisy.beauty.at<cv::Vec3f>(y, x);
                pixel += cv::Vec3f(n, n, n);
            }
        const fs::path path = folder / ("seed" + std::to_string(replicate) + "-" + std::to_string(seed) + ".exr");
        testing::WriteOptions options;
        options.stringAttributes["skinlab:pathtraced"] = nlohmann::json{{"samples", 64}, {"seed", seed}}.dump();
        options.stringAttributes["skinlab:resolved"] = nlohmann::json{
            {"model", scene},
            {"sss", {{"method", "pathtraced"}}},
            {"pathtraced", {{"seed", seed}}}}.dump();
        testing::writeSyntheticExr(path, noisy, options);
        return path;
    }
    // The noise-free render with `offset` added to every skin pixel (a luminance error of exactly `offset`).
    cv::Mat offsetLuminance(double offset) const {
        MetricRender render;
        render.beauty = truth.beauty.clone();
        for (int y = 0; y < truth.height; ++y)
            for (int x = 0; x < truth.width; ++x)
                if (truth.mask.at<float>(y, x) >= 0.5f)
                    render.beauty.at<cv::Vec3f>(y, x) += cv::Vec3f(float(offset), float(offset), float(offset));
        return renderLuminance(render, 1.0);
    }
    // The noise-free render with `offset` added to every skin pixel, written as a test render.
    fs::path writeOffset(double offset) const {
        testing::SyntheticRender render = truth;
        render.beauty = truth.beauty.clone();
        for (int y = 0; y < truth.height; ++y)
            for (int x = 0; x < truth.width; ++x)
                if (truth.mask.at<float>(y, x) >= 0.5f)
                    render.beauty.at<cv::Vec3f>(y, x) += cv::Vec3f(float(offset), float(offset), float(offset));
        const fs::path path = folder / ("offset-" + std::to_string(offset) + ".exr");
        testing::writeSyntheticExr(path, render);
        return path;
    }
    static constexpr std::size_t skin = 4;

    test_support::TempFolder temp;
    fs::path folder = temp.path();
    testing::DiscScene scene;
    testing::SyntheticRender truth;
};

TEST_F(DebiasedError, UnbiasedWhereOneNoisySeedIsNotAndTheJackknifeCoversIt) {
    const double sigma = 0.05;
    const double offset = 0.02; // true MSE on skin 4e-4, well below the noise variance 2.5e-3
    int covered = 0;
    double meanDebiased = 0.0;
    double meanPlain = 0.0;
    const int replicates = 12;
    for (int replicate = 0; replicate < replicates; ++replicate) {
        std::vector<fs::path> seeds;
        for (int seed = 0; seed < 4; ++seed) seeds.push_back(writeSeed(seed, sigma, replicate));
        const SeededTruth seeded = loadSeededTruth(seeds, 1.0, 0.0);
        const DebiasedScores scores = scoreDebiased(seeded, offsetLuminance(offset), "offset.exr");
        ASSERT_EQ(scores.mse[skin].leaveOneOut.size(), 4u);
        ASSERT_GT(scores.pixels[skin], 1000u);
        meanDebiased += scores.mse[skin].value / replicates;
        meanPlain += scores.plainMse[skin] / replicates;
        if (std::abs(scores.mse[skin].value - offset * offset) <= 2.5 * scores.mse[skin].standardError) ++covered;
    }
    // One noisy seed adds its variance to the error; the pairs of seeds do not.
    EXPECT_NEAR(meanPlain, offset * offset + sigma * sigma, 0.1 * sigma * sigma);
    EXPECT_NEAR(meanDebiased, offset * offset, 0.1 * offset * offset);
    EXPECT_GE(covered, 10) << "jackknife intervals covered the true squared error in " << covered << " of "
                           << replicates;
}

TEST_F(DebiasedError, PairedDifferencesAndRankingsFollowTheNoiseFreeImage) {
    std::vector<fs::path> seeds;
    for (int seed = 0; seed < 4; ++seed) seeds.push_back(writeSeed(seed, 0.05));
    const SeededTruth seeded = loadSeededTruth(seeds, 1.0, 0.0);
    // Five conditions whose true errors grow 0.004 … 0.02; the compared truth ranks them the same way.
    std::vector<DebiasedScores> scores;
    std::vector<double> other;
    for (int k = 1; k <= 5; ++k) {
        scores.push_back(scoreDebiased(seeded, offsetLuminance(0.004 * k), "c" + std::to_string(k)));
        other.push_back(k * 1.0);
    }
    const JackknifeEstimate difference = debiasedDifference(scores[4], scores[0], skin);
    EXPECT_NEAR(difference.value, 0.02 * 0.02 - 0.004 * 0.004, 3.0 * difference.standardError + 1e-6);
    EXPECT_GT(difference.value, 1.96 * difference.standardError);
    const RankingAgreement agreement = rankingAgreement(scores, other, skin);
    EXPECT_EQ(agreement.conditions, 5u);
    EXPECT_DOUBLE_EQ(agreement.tau.value, 1.0);
    EXPECT_EQ(agreement.tau.leaveOneOut.size(), 4u);
    EXPECT_GE(agreement.separatedPairs, 8u);
    EXPECT_EQ(agreement.concordantSeparated, agreement.separatedPairs);
    // The reversed ranking disagrees completely.
    std::vector<double> reversed(other.rbegin(), other.rend());
    EXPECT_DOUBLE_EQ(rankingAgreement(scores, reversed, skin).tau.value, -1.0);
}

// Colour beside luminance: an error in red alone is a fifth of itself in Y (Rec. 709: 0.2126), the whole of itself
// in R, nothing in G and B, and a CIELAB difference; every channel debiased as Y is.
TEST_F(DebiasedError, ScoresEachChannelAndCielabBesideLuminance) {
    std::vector<fs::path> seeds;
    for (int seed = 0; seed < 4; ++seed) seeds.push_back(writeSeed(seed, 0.03));
    const SeededTruth seeded = loadSeededTruth(seeds, 1.0, 0.0);
    const double offset = 0.05;
    MetricRender render;
    render.beauty = truth.beauty.clone();
    for (int y = 0; y < truth.height; ++y)
        for (int x = 0; x < truth.width; ++x)
            if (truth.mask.at<float>(y, x) >= 0.5f) render.beauty.at<cv::Vec3f>(y, x)[0] += float(offset);
    const DebiasedScores scores = scoreDebiased(seeded, renderQuantities(render, 1.0), "red.exr");
    const auto& y = scores.quantityMse[0][skin];
    const auto& red = scores.quantityMse[1][skin];
    const auto& green = scores.quantityMse[2][skin];
    const auto& lab = scores.quantityMse[4][skin];
    EXPECT_DOUBLE_EQ(y.value, scores.mse[skin].value);
    EXPECT_NEAR(y.value, 0.2126 * 0.2126 * offset * offset, 3.0 * y.standardError + 1e-7);
    EXPECT_NEAR(red.value, offset * offset, 3.0 * red.standardError + 1e-6);
    EXPECT_NEAR(green.value, 0.0, 3.0 * green.standardError + 1e-7);
    EXPECT_GT(red.value, 10.0 * y.value);
    EXPECT_GT(lab.value, 5.0 * lab.standardError);
    // One noisy seed alone adds the noise variance, 0.03², to the red channel's error.
    EXPECT_GT(scores.quantityPlainMse[1][skin], offset * offset + 0.5 * 0.03 * 0.03);
    EXPECT_EQ(scores.pairTerms[1][skin].size(), 6u);
}

// The seeds' mean as the truth of the error metrics: its pixels are the mean of the seeds', its squared error against
// the noise-free image is the noise variance over the seeds (estimated from the seeds' pairs, and measured against
// independent seeds), and the outputs say which truth was used and whether it is precise enough.
TEST_F(DebiasedError, TheSeedMeanIsATruthWithTheNoiseVarianceOverItsSeeds) {
    const double sigma = 0.05;
    std::vector<fs::path> truthSeeds;
    std::vector<fs::path> independent;
    for (int seed = 0; seed < 4; ++seed) truthSeeds.push_back(writeSeed(seed, sigma));
    for (int seed = 4; seed < 8; ++seed) independent.push_back(writeSeed(seed, sigma));
    const fs::path truthPath = folder / "truth.exr";
    const nlohmann::json record = writeSeedMean(truthSeeds, truthPath);
    EXPECT_EQ(record["kind"], "pathtraced-seed-mean");
    EXPECT_EQ(record["seeds"], nlohmann::json::array({0, 1, 2, 3}));
    EXPECT_EQ(describeTruth(truthPath), record);
    EXPECT_EQ(describeTruth(truthSeeds[0])["method"], "pathtraced");
    EXPECT_EQ(describeTruth(truthSeeds[0])["seed"], 0);

    // The beauty is the seeds' mean, pixel for pixel; depth and mask are the first seed's.
    const MetricRender mean = loadMetricRender(truthPath, RenderRole::reference);
    double largest = 0.0;
    std::vector<MetricRender> seeds;
    for (const fs::path& path : truthSeeds) seeds.push_back(loadMetricRender(path, RenderRole::reference));
    for (int y = 0; y < truth.height; y += 7)
        for (int x = 0; x < truth.width; x += 5) {
            float sum = 0.0f;
            for (const MetricRender& seed : seeds) sum += seed.beauty.at<cv::Vec3f>(y, x)[0];
            largest = std::max(largest, double(std::abs(mean.beauty.at<cv::Vec3f>(y, x)[0] - sum / 4.0f)));
            EXPECT_EQ(mean.mask.at<float>(y, x), seeds[0].mask.at<float>(y, x));
        }
    EXPECT_LT(largest, 1e-6);

    // From the pairs of the independent seeds: the mean of four has σ²/4 of squared error.
    const SeededTruth seeded = loadSeededTruth(independent, 1.0, 0.0);
    const JackknifeEstimate estimated = seedMeanMse(seeded, 0, skin);
    EXPECT_NEAR(estimated.value, sigma * sigma / 4.0, 0.1 * sigma * sigma / 4.0);
    EXPECT_EQ(estimated.leaveOneOut.size(), 4u);

    // Measured: the seed mean as the compared truth against the independent seeds. Conditions 0.05 and 0.08 from
    // the noise-free image: the best one's MSE 2.5e-3, the truth's 6.25e-4, a ratio of 0.25.
    DebiasedRunOptions options;
    options.compareReference = truthPath;
    options.agreement.bootstrapReplicates = 0;
    const DebiasedRun run =
        runDebiasedMetrics(independent, {writeOffset(0.05), writeOffset(0.08)}, options, folder / "debiased");
    ASSERT_TRUE(run.compared);
    const JackknifeEstimate& measured = run.compared->mse[skin];
    EXPECT_NEAR(measured.value, sigma * sigma / 4.0, 3.0 * measured.standardError + 0.1 * sigma * sigma / 4.0);
    const nlohmann::json precision =
        nlohmann::json::parse(readFile(folder / "debiased" / "debiased.json"))["truth_precision"];
    EXPECT_EQ(precision["seeds"], 4);
    const nlohmann::json& y = precision["regions"]["skin"]["Y"];
    EXPECT_NEAR(y["best_condition_mse"].get<double>(), 0.05 * 0.05, 3.0 * run.tests[0].mse[skin].standardError);
    EXPECT_NEAR(y["seed_mean"]["ratio_to_best_condition"].get<double>(), 0.25, 0.05);
    EXPECT_TRUE(y["seed_mean"]["precise_enough"].get<bool>());
    EXPECT_NEAR(y["compared_reference"]["ratio_to_best_condition"].get<double>(), 0.25, 0.05);
    EXPECT_TRUE(y["compared_reference"]["precise_enough"].get<bool>());
    // One seed alone (σ² = 2.5e-3, the best condition's own MSE) is not precise enough.
    DebiasedRunOptions single;
    single.compareReference = independent[0];
    single.agreement.bootstrapReplicates = 0;
    runDebiasedMetrics(truthSeeds, {writeOffset(0.05), writeOffset(0.08)}, single, folder / "single");
    const nlohmann::json one =
        nlohmann::json::parse(readFile(folder / "single" / "debiased.json"))["truth_precision"]["regions"]["skin"]["Y"];
    EXPECT_GT(one["compared_reference"]["ratio_to_best_condition"].get<double>(), 0.5);
    EXPECT_FALSE(one["compared_reference"]["precise_enough"].get<bool>());

    // Error metrics against the seed mean say which truth they used.
    runMetrics(planFileComparisons(truthPath, {writeOffset(0.05)}), {}, folder / "metrics");
    const nlohmann::json metrics = nlohmann::json::parse(readFile(folder / "metrics" / "metrics.json"));
    EXPECT_EQ(metrics["comparisons"][0]["reference"]["truth"], record);
}

TEST_F(DebiasedError, TheSeedMeanRefusesOtherScenesRepeatedSeedsAndOtherRenders) {
    const fs::path a = writeSeed(0, 0.01);
    const fs::path b = writeSeed(1, 0.01);
    const auto refused = [&](const std::vector<fs::path>& seeds, const std::string& expected) {
        try {
            writeSeedMean(seeds, folder / "mean.exr");
            ADD_FAILURE() << "accepted; expected: " << expected;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
            EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
        }
        EXPECT_FALSE(fs::exists(folder / "mean.exr"));
    };
    refused({a}, "at least two");
    refused({a, writeSeed(1, 0.01, 1, "ear")}, "seed1-1.exr: skinlab:resolved: differs from");
    refused({a, b, writeSeed(0, 0.01, 2)}, "seed2-0.exr: skinlab:pathtraced: seed 0 is given twice");
    const fs::path plain = folder / "plain.exr";
    testing::writeSyntheticExr(plain, truth);
    refused({a, plain}, "plain.exr: skinlab:pathtraced: metadata attribute is missing");
}

TEST(KendallTau, TiesAndKnownValues) {
    EXPECT_DOUBLE_EQ(kendallTauB({1, 2, 3, 4}, {1, 2, 3, 4}), 1.0);
    EXPECT_DOUBLE_EQ(kendallTauB({1, 2, 3, 4}, {4, 3, 2, 1}), -1.0);
    // scipy.stats.kendalltau([1, 2, 3, 4, 5], [3, 1, 2, 5, 4]) = 0.4
    EXPECT_NEAR(kendallTauB({1, 2, 3, 4, 5}, {3, 1, 2, 5, 4}), 0.4, 1e-12);
    // With ties: scipy.stats.kendalltau([1, 1, 2, 3], [1, 2, 2, 3]) = 0.8
    EXPECT_NEAR(kendallTauB({1, 1, 2, 3}, {1, 2, 2, 3}), 0.8, 1e-12);
    EXPECT_TRUE(std::isnan(kendallTauB({1, 1}, {2, 3})));
}

TEST_F(DebiasedError, RefusesOneSeedRepeatedSeedsAndOtherSizes) {
    const fs::path a = writeSeed(0, 0.01);
    const fs::path b = writeSeed(1, 0.01);
    try {
        loadSeededTruth({a}, 1.0, 0.0);
        FAIL() << "one seed accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--reference-seeds"), std::string::npos) << e.what();
    }
    try {
        loadSeededTruth({a, b, a}, 1.0, 0.0);
        FAIL() << "a repeated seed accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("given twice"), std::string::npos) << e.what();
    }
    testing::DiscScene small = scene;
    small.size = 64;
    const fs::path other = folder / "small.exr";
    testing::writeSyntheticExr(other, testing::renderDiscScene(small));
    try {
        loadSeededTruth({a, other}, 1.0, 0.0);
        FAIL() << "a seed of another size accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("small.exr"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("64x64"), std::string::npos) << e.what();
    }
}

} // namespace
} // namespace skinlab::metrics
