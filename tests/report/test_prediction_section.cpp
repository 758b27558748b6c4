// Predictions with each participant's own pixels per degree (report/prediction_section.h) on a tiny set written
// here: at the display model's own ppd nothing moves; at another ppd the predictions move, and each is the
// ColorVideoVDP JOD of the same pair on that geometry.
#include "report/prediction_section.h"

#include "analysis/agreement/metric_agreement.h"
#include "analysis/scaling/bootstrap.h"
#include "analysis/scaling/simulation.h"

#include "analysis/metrics/cvvdp.h"
#include "analysis/metrics/metric_render.h"
#include "tests/common/temp_folder.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <filesystem>
#include <random>

namespace fs = std::filesystem;

namespace {

// A textured image and a blurred copy: a difference ColorVideoVDP sees, more at a coarse ppd than at a fine one.
void writeSet(const fs::path& folder) {
    fs::create_directories(folder / "png");
    cv::Mat texture(96, 128, CV_8UC3);
    std::mt19937 random(7);
    for (int y = 0; y < texture.rows; ++y)
        for (int x = 0; x < texture.cols; ++x)
            texture.at<cv::Vec3b>(y, x) =
                cv::Vec3b(static_cast<uchar>(60 + random() % 140), static_cast<uchar>(60 + random() % 140), 128);
    cv::Mat blurred;
    cv::GaussianBlur(texture, blurred, {0, 0}, 1.5);
    cv::imwrite((folder / "png/ref.png").string(), texture);
    cv::imwrite((folder / "png/test.png").string(), blurred);
}

} // namespace

TEST(PredictionSection, ParticipantsOwnPixelsPerDegreeMovesThePredictions) {
    const skinlab::test_support::TempFolder temp;
    const fs::path& folder = temp.path();
    writeSet(folder);
    const skinlab::metrics::CvvdpDisplay model = skinlab::metrics::cvvdpDisplay("standard_fhd");
    auto jodAt = [&](double ppd) {
        skinlab::metrics::CvvdpDisplayOverrides overrides;
        overrides.pixelsPerDegree = ppd;
        const auto load = [&](const char* name) {
            return skinlab::metrics::loadMetricRender(folder / "png" / name, skinlab::metrics::RenderRole::test,
                                                      skinlab::metrics::ImageEncoding::srgb)
                .beauty;
        };
        return skinlab::metrics::cvvdp(load("ref.png"), load("test.png"),
                                       skinlab::metrics::applyCvvdpOverrides(model, overrides), false)
            .jod;
    };
    const double predicted = jodAt(model.pixelsPerDegree);
    // Two entries of contract 2 (formats/stimulus_manifest.h), written by its one writer.
    skinlab::formats::ManifestEntry reference, test;
    for (auto [entry, id] : {std::pair{&reference, "ref"}, std::pair{&test, "test"}}) {
        entry->id = id;
        entry->files = {std::string("exr/") + id + ".exr", std::string("png/") + id + ".png"};
        entry->sha256 = {std::string(64, '0'), std::string(64, '0')};
        entry->block = "b";
        entry->width = 128;
        entry->height = 96;
    }
    reference.reference = true;
    test.predicted = skinlab::formats::Prediction{"ColorVideoVDP v0.5.6", "standard_fhd",      "ref", predicted,
                                                  std::string(64, '0'),   std::string(64, '0')};
    const nlohmann::json manifest = {
        {"stimuli", {skinlab::formats::toJson(reference), skinlab::formats::toJson(test)}}};
    const auto rows = skinlab::report::participantPredictions(
        manifest, folder, {{"P001", model.pixelsPerDegree}, {"P002", 20.0}, {"P003", 80.0}});
    ASSERT_EQ(rows.size(), 3u);
    EXPECT_EQ(rows[0].observer, "P001");
    EXPECT_NEAR(rows[0].meanChange, 0.0, 1e-12) << "the model's own ppd predicts what the set did";
    EXPECT_GT(rows[1].meanChange, 0.01) << "20 ppd: coarser pixels, a more visible blur";
    EXPECT_GT(rows[2].meanChange, 0.01) << "80 ppd: finer pixels, a less visible blur";
    EXPECT_NEAR(rows[1].largestChange, std::abs(jodAt(20.0) - predicted), 1e-9);
    EXPECT_LT(jodAt(20.0), predicted);
    EXPECT_GT(jodAt(80.0), predicted);
    EXPECT_FALSE(rows[1].orderChanged); // one condition: no order to change
    EXPECT_EQ(rows[1].stimuli, 1);
}

namespace {

namespace scaling = skinlab::analysis::scaling;

// A simulated 5-condition study (10 observers, 2 trials per pair) whose truth is `truth`, scaled as `analyze
// scale` does, and its agreement with `predicted`.
skinlab::report::PredictionAgreement simulatedAgreement(const std::vector<double>& truth,
                                                        const std::vector<double>& predicted, std::uint64_t seed,
                                                        int samples) {
    scaling::SimulationDesign design;
    design.trueScores = truth;
    design.observers = 10;
    design.trialsPerPair = 2;
    const scaling::SimulatedBlock simulated = scaling::simulateBlock(design, seed);
    scaling::AnalysisOptions options;
    options.bootstrap.samples = 200;
    options.bootstrap.threads = 1;
    const scaling::BlockAnalysis block = scaling::analyzeBlock(simulated.block, options);
    skinlab::report::PredictionOptions agreementOptions;
    agreementOptions.samples = samples;
    agreementOptions.seed = seed;
    return *skinlab::report::blockPredictionAgreement(block, predicted, &simulated.block, agreementOptions);
}

} // namespace

TEST(PredictionSection, TheAnchorIsNotAFixedPointAndSlopeAndRmseCarryIntervals) {
    const std::vector<double> truth = {0.0, 0.6, 1.2, 1.8, 2.4};
    const skinlab::report::PredictionAgreement a = simulatedAgreement(truth, truth, 11, 400);
    ASSERT_EQ(a.conditions.size(), 5u);
    EXPECT_EQ(a.anchor, "c4"); // the largest prediction
    // The anchor has a measured value with its own interval, not 0 with [0, 0].
    EXPECT_LT(a.low[4], a.measured[4]);
    EXPECT_GT(a.high[4], a.measured[4]);
    // Measured values are the scores shifted onto the predictions' mean.
    double predictedMean = 0.0, measuredMean = 0.0;
    for (std::size_t i = 0; i < 5; ++i) predictedMean += a.predicted[i] / 5.0, measuredMean += a.measured[i] / 5.0;
    EXPECT_NEAR(predictedMean, measuredMean, 1e-12);
    ASSERT_TRUE(std::isfinite(a.slopeLow) && std::isfinite(a.slopeHigh));
    EXPECT_LT(a.slopeLow, a.slope);
    EXPECT_GT(a.slopeHigh, a.slope);
    EXPECT_LT(a.rmseLow, a.rmseHigh);
    EXPECT_FALSE(a.overConditions); // 5 conditions: over observers only
    // Spearman's interval agrees with its exact p: it excludes 0 exactly when p < 0.05.
    EXPECT_EQ(a.spearmanLow > 0.0, a.spearmanP < 0.05) << a.spearman << " p " << a.spearmanP;
}

TEST(PredictionSection, SlopeIntervalsCoverInSimulation) {
    // 60 simulated studies whose truth is the prediction (true slope 1): how often the slope's 95 % bootstrap
    // interval holds 1 (docs/report.md records the figure). Seeded; a construction without the observers'
    // variance (no interval, or a zero-width one) covers nothing.
    const std::vector<double> truth = {0.0, 0.6, 1.2, 1.8, 2.4};
    int covered = 0;
    const int studies = 60;
    for (int study = 0; study < studies; ++study) {
        const auto a = simulatedAgreement(truth, truth, scaling::mixSeed(77, study), 200);
        covered += a.slopeLow <= 1.0 && 1.0 <= a.slopeHigh;
    }
    EXPECT_GE(covered, studies * 85 / 100) << covered << " of " << studies;
}

TEST(PredictionSection, RmseIntervalsCoverInSimulation) {
    // Truth = prediction (the circular `--truth predicted` case): the true RMSE is 0, on the boundary, and the
    // measured RMSE is noise alone. The bias-corrected bootstrap interval alone started above 0 in 13 % of 1000
    // such studies; with the test of RMSE = 0 deciding its low end it holds 0 at about the stated level
    // (bench_prediction_coverage has the figures, docs/report.md records them).
    const std::vector<double> truth = {0.0, 0.6, 1.2, 1.8, 2.4};
    int covered = 0;
    const int studies = 60;
    for (int study = 0; study < studies; ++study) {
        const auto a = simulatedAgreement(truth, truth, scaling::mixSeed(78, study), 200);
        covered += a.rmseLow == 0.0 && a.rmseHigh >= a.rmse;
    }
    EXPECT_GE(covered, studies * 93 / 100) << covered << " of " << studies;
    // A prediction that misses two conditions by 0.5 JOD: the RMSE's interval is above 0 in most studies.
    const std::vector<double> predicted = {0.0, 0.6, 1.2, 1.8, 2.4}, departing = {0.0, 1.1, 0.7, 1.8, 2.4};
    int detected = 0;
    for (int study = 0; study < 20; ++study)
        detected += simulatedAgreement(departing, predicted, scaling::mixSeed(79, study), 200).rmseLow > 0.0;
    EXPECT_GE(detected, 10) << detected << " of 20";
}

TEST(PredictionSection, CircularTruthIsDisclosed) {
    const std::vector<double> truth = {0.0, 0.6, 1.2, 1.8, 2.4};
    const auto a = simulatedAgreement(truth, truth, 5, 100);
    const std::string real = skinlab::report::predictionSectionHtml({a}, "standard_fhd", {}, 0);
    const std::string simulated = skinlab::report::predictionSectionHtml({a}, "standard_fhd", {}, 10);
    EXPECT_EQ(real.find("circular"), std::string::npos);
    EXPECT_NE(simulated.find("--truth predicted</code>), the agreement below is circular"), std::string::npos);
    EXPECT_NE(simulated.find("exact p = "), std::string::npos);
}

TEST(SpearmanInterval, ConsistentWithTheExactPAtFewConditions) {
    // Every attainable ρ̂ at 4–7 conditions: the interval excludes 0 exactly when the exact two-sided p ≤ 0.05.
    // Fisher's z with Bonett–Wright gave [0.91, 1.00] for ρ̂ = 1 at 5 conditions (exact p = 2/120).
    for (int n = 4; n <= 7; ++n) {
        std::vector<double> x(static_cast<std::size_t>(n));
        for (int i = 0; i < n; ++i) x[i] = i;
        std::vector<double> y = x;
        do {
            const double rho = skinlab::analysis::agreement::spearmanCorrelation(x, y);
            const double p = skinlab::analysis::agreement::correlationPValue(x, y, true);
            const auto [low, high] = skinlab::analysis::agreement::spearmanExactInterval(rho, n, 0.95);
            EXPECT_EQ(low > 0.0 || high < 0.0, p <= 0.05 + 1e-12) << "n " << n << " rho " << rho << " p " << p;
            EXPECT_LE(low, rho + 1e-12);
            EXPECT_GE(high, rho - 1e-12);
        } while (std::next_permutation(y.begin(), y.end()) && n <= 5);
    }
    const auto [low, high] = skinlab::analysis::agreement::spearmanExactInterval(1.0, 5, 0.95);
    EXPECT_EQ(high, 1.0);
    EXPECT_GT(low, 0.0);
    EXPECT_LT(low, 0.79) << "a true ρ of 0.79 gives ρ̂ = 1 in 14 % of 5-condition studies";
}
