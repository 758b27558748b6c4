// Predictions with each participant's own pixels per degree (report/prediction_section.h) on a tiny set written
// here: at the display model's own ppd nothing moves; at another ppd the predictions move, and each is the
// ColorVideoVDP JOD of the same pair on that geometry.
#include "report/prediction_section.h"

#include "analysis/metrics/cvvdp.h"
#include "analysis/metrics/metric_render.h"

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
    const fs::path folder = fs::temp_directory_path() / ("skinlab-prediction-" + std::to_string(::getpid()));
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
    const nlohmann::json manifest = {
        {"stimuli",
         {{{"id", "ref"}, {"block", "b"}, {"reference", true}, {"files", {{"png", "png/ref.png"}}}},
          {{"id", "test"},
           {"block", "b"},
           {"reference", false},
           {"files", {{"png", "png/test.png"}}},
           {"predicted", {{"jod", predicted}, {"display", "standard_fhd"}, {"reference", "ref"}}}}}}};
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
    fs::remove_all(folder);
}
