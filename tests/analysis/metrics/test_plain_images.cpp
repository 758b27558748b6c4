// `analyze metrics` on plain images (PNG, JPEG, RGB-only EXR): the image-wide scores, checked against the metric
// functions applied to the decoded pixels; skin and band scores left out; the sRGB/linear decoding as stated by the
// file or chosen; FLIP in the outputs.
#include "analysis/metrics/colour_space.h"
#include "analysis/metrics/flip.h"
#include "analysis/metrics/image_quality.h"
#include "analysis/metrics/metrics_run.h"

#include "common/error.h"
#include "common/files.h"
#include "synthetic_render.h"
#include "tests/common/temp_folder.h"

#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

namespace skinlab::metrics {
namespace {
namespace fs = std::filesystem;

class PlainImages : public ::testing::Test {
protected:
    // A passing test leaves nothing behind; a failing one keeps its files to look at.
    void TearDown() override { temp.keep = HasFailure(); }
    void SetUp() override {
        output = folder / "out";
        // An 8-bit RGB gradient with a square, and a copy with the square brighter (BGR for OpenCV).
        reference.create(60, 80, CV_8UC3);
        for (int y = 0; y < reference.rows; ++y)
            for (int x = 0; x < reference.cols; ++x)
                reference.at<cv::Vec3b>(y, x) = {static_cast<uint8_t>(40 + x), static_cast<uint8_t>(90 + y),
                                                 static_cast<uint8_t>(150)};
        test = reference.clone();
        test(cv::Rect(20, 15, 25, 20)) += cv::Scalar(30, 20, 10);
    }
    // The 8-bit values as linear RGB (R, G, B order) through the sRGB EOTF, or as they are.
    static cv::Mat linear(const cv::Mat& bgr8, bool srgb) {
        cv::Mat out(bgr8.size(), CV_64FC3);
        for (int y = 0; y < bgr8.rows; ++y)
            for (int x = 0; x < bgr8.cols; ++x) {
                cv::Vec3b v = bgr8.at<cv::Vec3b>(y, x);
                for (int c = 0; c < 3; ++c) {
                    double e = v[2 - c] / 255.0;
                    out.at<cv::Vec3d>(y, x)[c] =
                        srgb ? (e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4)) : e;
                }
            }
        return out;
    }
    static cv::Mat display(const cv::Mat& linearRgb) {
        cv::Mat out(linearRgb.size(), CV_64FC3);
        for (int y = 0; y < linearRgb.rows; ++y)
            for (int x = 0; x < linearRgb.cols; ++x)
                for (int c = 0; c < 3; ++c)
                    out.at<cv::Vec3d>(y, x)[c] = 255.0 * encodeSrgb(linearRgb.at<cv::Vec3d>(y, x)[c]);
        return out;
    }
    // RGB-only float EXR of linear values.
    fs::path writeExr(const std::string& name, const cv::Mat& linearRgb) {
        fs::path path = folder / name;
        cv::Mat f;
        linearRgb.convertTo(f, CV_32FC3);
        auto out = OIIO::ImageOutput::create(path.string());
        OIIO::ImageSpec spec(f.cols, f.rows, 3, OIIO::TypeDesc::FLOAT);
        EXPECT_TRUE(out->open(path.string(), spec));
        EXPECT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, f.data));
        out->close();
        return path;
    }
    test_support::TempFolder temp;
    fs::path folder = temp.path(), output;
    cv::Mat reference, test;
};

TEST_F(PlainImages, PngPairGetsTheImageWideScoresAndNoBands) {
    fs::path referencePath = folder / "photo.png", testPath = folder / "edited.png";
    ASSERT_TRUE(cv::imwrite(referencePath.string(), reference));
    ASSERT_TRUE(cv::imwrite(testPath.string(), test));
    auto records = runMetrics(planFileComparisons(referencePath, {testPath}), {}, output);
    ASSERT_EQ(records.size(), 1u);
    EXPECT_FALSE(records[0].bandsMeasured);

    cv::Mat referenceLinear = linear(reference, true), testLinear = linear(test, true);
    // The 8-bit values come back exactly through decode and re-encode, so PSNR equals that of the 8-bit data.
    double psnr = peakSignalToNoiseRatio(display(referenceLinear), display(testLinear));
    // FLIP at the display's pixels per degree (one viewing geometry with ColorVideoVDP).
    double flip = flipMean(flipErrorMap(referenceLinear, testLinear, cvvdpDisplay("standard_fhd").pixelsPerDegree));
    nlohmann::json json = nlohmann::json::parse(readFile(output / "metrics.json"));
    const auto& comparison = json["comparisons"][0];
    EXPECT_NEAR(comparison["image"]["psnr_db"].get<double>(), psnr, 1e-4);
    EXPECT_NEAR(comparison["image"]["flip_mean"].get<double>(), flip, 1e-6);
    EXPECT_GT(comparison["image"]["flip_mean"].get<double>(), 0.0);
    EXPECT_GT(comparison["image"]["delta_e00_mean"].get<double>(), 0.0);
    EXPECT_LT(comparison["image"]["ssim"].get<double>(), 1.0);
    EXPECT_EQ(comparison["bands_measured"], false);
    EXPECT_TRUE(comparison["skin"].is_null());
    EXPECT_TRUE(comparison["bands"].is_null());
    EXPECT_EQ(json["settings"]["encoding"], "auto");
    EXPECT_TRUE(fs::exists(output / "heatmaps/edited.png"));
    EXPECT_TRUE(fs::exists(output / "heatmaps/edited.flip.png"));
    EXPECT_TRUE(fs::exists(output / "heatmaps/edited.cvvdp.png"));
    // ColorVideoVDP on the default display (standard_fhd), as the library computes it.
    cv::Mat referenceFloat, testFloat;
    referenceLinear.convertTo(referenceFloat, CV_32FC3);
    testLinear.convertTo(testFloat, CV_32FC3);
    const CvvdpResult visibility = cvvdp(referenceFloat, testFloat, cvvdpDisplay("standard_fhd"));
    EXPECT_NEAR(comparison["cvvdp_jod"].get<double>(), visibility.jod, 1e-4);
    EXPECT_LT(comparison["cvvdp_jod"].get<double>(), 10.0);
    EXPECT_NEAR(comparison["image"]["cvvdp_map_mean"].get<double>(), cvvdpMapMean(visibility.map), 1e-4);
    EXPECT_EQ(json["settings"]["cvvdp"]["display"], "standard_fhd");
    std::string csv = readFile(output / "metrics.csv");
    EXPECT_NE(csv.find(",heatmaps/edited.png,heatmaps/edited.flip.png,heatmaps/edited.cvvdp.png,0\n"),
              std::string::npos)
        << csv;
}

TEST_F(PlainImages, JpegIsReadAsSrgb) {
    fs::path referencePath = folder / "a.jpg", testPath = folder / "b.jpg";
    ASSERT_TRUE(cv::imwrite(referencePath.string(), reference, {cv::IMWRITE_JPEG_QUALITY, 100}));
    ASSERT_TRUE(cv::imwrite(testPath.string(), reference, {cv::IMWRITE_JPEG_QUALITY, 100}));
    MetricRender loaded = loadMetricRender(referencePath, RenderRole::reference);
    EXPECT_TRUE(loaded.plain);
    EXPECT_EQ(loaded.encoding, ImageEncoding::srgb);
    auto records = runMetrics(planFileComparisons(referencePath, {testPath}), {}, output);
    EXPECT_EQ(records[0].image.flipMean, 0.0);
    EXPECT_TRUE(std::isinf(records[0].image.psnrDecibels));
}

// An RGB-only EXR is linear by default; --encoding srgb decodes it as sRGB instead (the scores change), and a PNG
// read with --encoding linear matches the EXR holding the raw 8-bit values / 255.
TEST_F(PlainImages, EncodingIsStatedOrChosen) {
    fs::path exrReference = writeExr("ref.exr", linear(reference, false));
    fs::path exrTest = writeExr("test.exr", linear(test, false));
    EXPECT_EQ(loadMetricRender(exrReference, RenderRole::reference).encoding, ImageEncoding::linear);
    auto asLinear = runMetrics(planFileComparisons(exrReference, {exrTest}), {}, output);

    fs::path pngReference = folder / "ref.png", pngTest = folder / "test.png";
    ASSERT_TRUE(cv::imwrite(pngReference.string(), reference));
    ASSERT_TRUE(cv::imwrite(pngTest.string(), test));
    MetricsRunOptions linearOption;
    linearOption.metric.encoding = ImageEncoding::linear;
    auto pngLinear = runMetrics(planFileComparisons(pngReference, {pngTest}), linearOption, folder / "out2");
    EXPECT_NEAR(pngLinear[0].image.flipMean, asLinear[0].image.flipMean, 1e-6);
    EXPECT_NEAR(pngLinear[0].image.deltaE00Mean, asLinear[0].image.deltaE00Mean, 1e-4);

    MetricsRunOptions srgbOption;
    srgbOption.metric.encoding = ImageEncoding::srgb;
    auto exrSrgb = runMetrics(planFileComparisons(exrReference, {exrTest}), srgbOption, folder / "out3");
    auto pngAuto = runMetrics(planFileComparisons(pngReference, {pngTest}), {}, folder / "out4");
    EXPECT_NEAR(exrSrgb[0].image.flipMean, pngAuto[0].image.flipMean, 1e-6);
    EXPECT_GT(std::fabs(exrSrgb[0].image.flipMean - asLinear[0].image.flipMean), 1e-4);
}

// A skinlab render with some of its AOVs is not plain: the missing one is still an error.
TEST_F(PlainImages, PartialSkinlabRenderIsStillAnError) {
    testing::DiscScene scene;
    scene.size = 32;
    auto render = testing::renderDiscScene(scene);
    fs::path noDepth = folder / "no-depth.exr";
    testing::writeSyntheticExr(noDepth, render, {{"depth.Z"}, {}});
    EXPECT_THROW(loadMetricRender(noDepth, RenderRole::reference), InputError);
}

TEST_F(PlainImages, BadEncodingAndPpdAreNamed) {
    try {
        parseImageEncoding("gamma");
        FAIL();
    } catch (const InputError& e) {
        EXPECT_STREQ(e.what(), "--encoding: \"gamma\" is not one of auto, srgb, linear");
    }
    fs::path referencePath = folder / "a.png";
    ASSERT_TRUE(cv::imwrite(referencePath.string(), reference));
    MetricsRunOptions options;
    options.metric.pixelsPerDegree = -1.0;
    try {
        runMetrics(planFileComparisons(referencePath, {referencePath.parent_path() / "a.png"}), options, output);
        FAIL();
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()), "--ppd: -1 must be a positive number");
    }
    EXPECT_FALSE(fs::exists(output));
}

} // namespace
} // namespace skinlab::metrics
