// [skin] through the renderer (docs/skin-tones.md): builtin:head's skin luminance spans at least 3× from the lightest
// to the darkest level, its procedural detail stays; the main pass's transmittance takes the tone's weights; the
// scanned head's albedo map is re-toned (skips without $SKINLAB_ASSETS). Small renders (64 px), label gl.
#include "render_test_support.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

using namespace skinlab::renderer;
using skinlab::renderer::test::ExrImage;
using skinlab::renderer::test::readExr;
using skinlab::test_support::TempFolder;

namespace {

ExrImage renderTone(const std::string& scene, const std::string& tone, const std::filesystem::path& exr,
                    std::vector<std::string> overrides = {}) {
    RenderRequest request;
    request.scene = scene;
    request.overrides = std::move(overrides);
    request.overrides.push_back("camera.view=\"close\"");
    // Per-pixel checks (albedo ratios, the mask's pixels): one sample per pixel, no edge pixel mixing skin and eye.
    request.overrides.push_back("render.antialiasing=\"none\"");
    if (!tone.empty()) request.overrides.push_back("skin.tone=\"" + tone + "\"");
    request.width = 64;
    request.height = 64;
    request.exrPath = exr;
    test::sharedRenderer()->render(request);
    return readExr(exr);
}

// Mean Rec. 709 luminance of `layer` (".R/.G/.B" or "" for the beauty) over the skin mask, and the pixel count.
std::pair<double, int> skinLuminance(const ExrImage& image, const std::string& layer) {
    const std::string prefix = layer.empty() ? "" : layer + ".";
    const auto& r = image.channels.at(prefix + "R");
    const auto& g = image.channels.at(prefix + "G");
    const auto& b = image.channels.at(prefix + "B");
    const auto& mask = image.channels.at("mask.Y");
    double sum = 0.0;
    int count = 0;
    for (std::size_t i = 0; i < mask.size(); ++i)
        if (mask[i] > 0.5f) {
            sum += 0.2126 * r[i] + 0.7152 * g[i] + 0.0722 * b[i];
            ++count;
        }
    return {count > 0 ? sum / count : 0.0, count};
}

} // namespace

TEST(SkinToneRender, BuiltinHeadSpansThreefoldInLuminanceAndKeepsItsDetail) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    (void)renderer;
    TempFolder folder("skin-tone-head");
    const ExrImage light = renderTone("builtin:head", "I", folder / "light.exr");
    const ExrImage dark = renderTone("builtin:head", "VI", folder / "dark.exr");
    const auto [lightBeauty, lightCount] = skinLuminance(light, "");
    const auto [darkBeauty, darkCount] = skinLuminance(dark, "");
    ASSERT_GT(lightCount, 500);
    EXPECT_EQ(lightCount, darkCount);
    EXPECT_GE(lightBeauty / darkBeauty, 3.0) << lightBeauty << " / " << darkBeauty;
    const double lightAlbedo = skinLuminance(light, "albedo").first;
    const double darkAlbedo = skinLuminance(dark, "albedo").first;
    EXPECT_GE(lightAlbedo / darkAlbedo, 3.0);
    // The procedural detail multiplies the tone's albedo: the albedo varies over the skin at both tones, by the
    // same relative amount (the albedo AOV of a texel is tone albedo × the same detail value).
    const auto& a = light.channels.at("albedo.G");
    const auto& b = dark.channels.at("albedo.G");
    const auto& mask = light.channels.at("mask.Y");
    double lowest = 1e9, highest = 0.0;
    for (std::size_t i = 0; i < mask.size(); ++i)
        if (mask[i] > 0.5f && b[i] > 0.0f) {
            const double r = a[i] / b[i];
            lowest = std::min(lowest, r);
            highest = std::max(highest, r);
        }
    EXPECT_NEAR(highest / lowest, 1.0, 0.02); // the same detail at both tones
    // Without [skin], the render is the scene's own skin (the default level differs from it).
    const ExrImage plain = renderTone("builtin:head", "", folder / "plain.exr");
    EXPECT_NE(skinLuminance(plain, "albedo").first, lightAlbedo);
}

TEST(SkinToneRender, TransmittanceTakesTheTonesWeights) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    (void)renderer;
    TempFolder folder("skin-tone-ear");
    const std::vector<std::string> on{"transmittance.enabled=true"};
    const ExrImage deon = renderTone("builtin:ear", "", folder / "deon.exr", on);
    const ExrImage light = renderTone("builtin:ear", "I", folder / "light.exr", on);
    const ExrImage dark = renderTone("builtin:ear", "VI", folder / "dark.exr", on);
    // Transmittance AOV (before the albedo): the darkest level's narrower profile lets less light through the fin
    // than the lightest level's wider one, in red, the channel that reaches farthest.
    double sumLight = 0.0, sumDark = 0.0, sumDeon = 0.0;
    for (std::size_t i = 0; i < light.channels.at("transmittance.R").size(); ++i) {
        sumLight += light.channels.at("transmittance.R")[i];
        sumDark += dark.channels.at("transmittance.R")[i];
        sumDeon += deon.channels.at("transmittance.R")[i];
    }
    EXPECT_GT(sumDeon, 0.0);
    EXPECT_GT(sumLight, sumDark);
    EXPECT_NE(sumLight, sumDeon);
}

TEST(SkinToneRender, ScannedHeadAlbedoMapIsRetoned) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    (void)renderer;
    const char* assets = std::getenv("SKINLAB_ASSETS");
    if (!assets || !*assets) GTEST_SKIP() << "SKINLAB_ASSETS is not set (the scanned head)";
    TempFolder folder("skin-tone-scan");
    const std::string scene = std::string(SKINLAB_SOURCE_DIR) + "/renderer/scenes/lee-perry-smith.toml";
    const ExrImage plain = renderTone(scene, "", folder / "plain.exr");
    const ExrImage light = renderTone(scene, "I", folder / "light.exr");
    const ExrImage dark = renderTone(scene, "VI", folder / "dark.exr");
    const double plainAlbedo = skinLuminance(plain, "albedo").first;
    const double lightAlbedo = skinLuminance(light, "albedo").first;
    const double darkAlbedo = skinLuminance(dark, "albedo").first;
    EXPECT_GE(lightAlbedo / darkAlbedo, 3.0) << lightAlbedo << " / " << darkAlbedo;
    EXPECT_NE(plainAlbedo, lightAlbedo);
}
