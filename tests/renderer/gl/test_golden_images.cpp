// Golden images of the built-in scenes and their named variants at 128×128 (label gl). The goldens are the beauty channels of
// tests/data/golden/NAME.exr (half float). Regenerate after an intended change with
//   SKINLAB_UPDATE_GOLDENS=1 ctest -R GoldenImages
// and review the new images before committing them. A failure writes NAME-actual.exr, NAME-expected.exr and
// NAME-diff.exr (absolute difference) into <build>/test-output/golden/.
#include "render_test_support.h"

#include <OpenImageIO/imageio.h>
#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace skinlab::renderer {
namespace {

using test::ExrImage;

// Tolerances, on linear beauty values (scene-referred; skin is about 0.1–1, highlights a few units):
//  - mean absolute difference ≤ 0.002: the whole image must agree to well below one 8-bit display step
//    (~0.004 at mid grey after tone mapping); catches any global change of lighting, exposure or albedo;
//  - max absolute difference ≤ 0.5 for all but 0.5 % of the channel values, and no value off by more than
//    4.0: a different Mesa/LLVM may rasterise a few silhouette or shadow-edge pixels differently (a pixel
//    flipping between skin and backdrop changes by its full contrast), but any structural change touches far
//    more than 0.5 % of the pixels or exceeds a specular highlight's range.
// On the same machine and Mesa version the render is bit-identical and every difference is 0.
constexpr double kMeanTolerance = 0.002;
constexpr double kPixelTolerance = 0.5;
constexpr double kOutlierFraction = 0.005;
constexpr double kMaxTolerance = 4.0;
constexpr int kSize = 128;

void writeRgb(const std::filesystem::path& path, int width, int height, const std::vector<float>& rgb, bool half) {
    std::filesystem::create_directories(path.parent_path());
    OIIO::ImageSpec spec(width, height, 3, half ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
    spec.attribute("compression", "zip");
    spec.attribute("DateTime", ""); // no timestamp: regenerating an unchanged golden gives the same bytes
    auto out = OIIO::ImageOutput::create(path.string());
    ASSERT_TRUE(out && out->open(path.string(), spec)) << path;
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, rgb.data()));
    out->close();
}

std::vector<float> readRgb(const std::filesystem::path& path, int& width, int& height) {
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) return {};
    width = in->spec().width;
    height = in->spec().height;
    std::vector<float> rgb(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3);
    in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, rgb.data());
    return rgb;
}

class GoldenImages : public ::testing::TestWithParam<std::string> {};

TEST_P(GoldenImages, BuiltinSceneMatchesItsGolden) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    const std::string name = GetParam();
    test::TempFolder folder("golden-" + name);
    RenderRequest request;
    request.scene = "builtin:" + name;
    // Without anti-aliasing: the goldens hold the shading of each pixel centre, so a change of the passes shows
    // wherever it happens; the resolve is checked against its known answer (test_antialiasing.cpp).
    request.overrides = {"render.antialiasing=none"};
    request.width = kSize;
    request.height = kSize;
    request.exrPath = folder / (name + ".exr");
    renderer->render(request);
    const ExrImage image = test::readExr(request.exrPath);
    std::vector<float> actual;
    for (std::size_t p = 0; p < image.channels.at("R").size(); ++p)
        for (const char* c : {"R", "G", "B"}) actual.push_back(image.channels.at(c)[p]);
    // Goldens are stored as half floats; compare against the actual values rounded the same way.
    const std::filesystem::path golden =
        std::filesystem::path(SKINLAB_SOURCE_DIR) / "tests/data/golden" / (name + ".exr");
    if (const char* update = std::getenv("SKINLAB_UPDATE_GOLDENS"); update && std::string(update) == "1") {
        writeRgb(golden, kSize, kSize, actual, true);
        GTEST_SKIP() << "SKINLAB_UPDATE_GOLDENS=1: wrote " << golden;
    }
    int width = 0, height = 0;
    const std::vector<float> expected = readRgb(golden, width, height);
    ASSERT_FALSE(expected.empty()) << "missing golden " << golden << " (create it with SKINLAB_UPDATE_GOLDENS=1)";
    ASSERT_EQ(width, kSize);
    ASSERT_EQ(height, kSize);

    double sum = 0, maximum = 0;
    std::size_t outliers = 0;
    std::vector<float> difference(actual.size());
    for (std::size_t i = 0; i < actual.size(); ++i) {
        // Half precision of the golden: relative 2^-11; values compared after the same rounding error budget.
        const double d = std::abs(static_cast<double>(actual[i]) - static_cast<double>(expected[i]));
        const double halfRounding = std::abs(static_cast<double>(expected[i])) * (1.0 / 2048.0);
        const double excess = std::max(0.0, d - halfRounding);
        difference[i] = static_cast<float>(d);
        sum += excess;
        maximum = std::max(maximum, excess);
        outliers += excess > kPixelTolerance;
    }
    const double mean = sum / static_cast<double>(actual.size());
    const double outlierFraction = static_cast<double>(outliers) / static_cast<double>(actual.size());
    const bool pass = mean <= kMeanTolerance && maximum <= kMaxTolerance && outlierFraction <= kOutlierFraction;
    if (!pass) {
        const auto out = std::filesystem::path(SKINLAB_BINARY_DIR) / "test-output/golden";
        writeRgb(out / (name + "-actual.exr"), kSize, kSize, actual, false);
        writeRgb(out / (name + "-expected.exr"), kSize, kSize, expected, false);
        writeRgb(out / (name + "-diff.exr"), kSize, kSize, difference, false);
        ADD_FAILURE() << name << ": mean |diff| " << mean << " (limit " << kMeanTolerance << "), max " << maximum
                      << " (limit " << kMaxTolerance << "), values off by > " << kPixelTolerance << ": "
                      << outlierFraction * 100 << " % (limit " << kOutlierFraction * 100 << " %); images in " << out;
    }
}

// The named variants halo-grey-backdrop and bleed-true-mask keep the goldens of the former halo and bleed defaults.
INSTANTIATE_TEST_SUITE_P(Builtin, GoldenImages,
                         ::testing::Values("halo", "bleed", "ear", "head", "halo-grey-backdrop", "bleed-true-mask"),
                         [](const ::testing::TestParamInfo<std::string>& param) {
                             std::string name = param.param; // a test name holds letters, digits and '_' only
                             std::replace(name.begin(), name.end(), '-', '_');
                             return name;
                         });

} // namespace
} // namespace skinlab::renderer
