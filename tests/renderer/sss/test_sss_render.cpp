// Whole renders with the SSS methods through the renderer's public API (label gl; llvmpipe in CI; small images):
// every method renders every builtin scene (and the scanned head when $SKINLAB_ASSETS is set), a uniformly lit
// plane keeps its mean, follow-surface stops light crossing the depth gap of builtin:halo.
#include "../gl/render_test_support.h"
#include "renderer/renderer.h"
#include "renderer/sss/sss_params.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <gtest/gtest.h>

namespace skinlab::renderer {
namespace {

using test::ExrImage;
using test::readExr;
using test::TempFolder;

// The methods of the shared blur passes, from the method table (renderer/sss/sss_params.h).
const std::vector<std::string> kMethods = renderer::sss::blurPassMethodNames();

ExrImage render(Renderer& renderer, const TempFolder& folder, const std::string& scene, const std::string& method,
                std::vector<std::string> overrides, int width, int height) {
    test::renderToExr(renderer, scene, method, std::move(overrides), width, height, folder / (method + ".exr"));
    return readExr(folder / (method + ".exr"));
}

double luminance(const ExrImage& image, int x, int y) { return test::diffuseLuminance(image, x, y); }

} // namespace

namespace {
// Renders `scene` with none and every method at 64×48 (both with `overrides`) and checks finite output, untouched
// non-skin pixels and that the SSS changed the skin.
void renderEveryMethod(Renderer& renderer, const std::string& scene, const std::vector<std::string>& overrides = {},
                       const std::vector<std::string>& methods = kMethods) {
    TempFolder folder("sss-every-scene");
    // The comparison without SSS gets the overrides that method none reads (the [sss] keys of the others would be
    // an error there; transmittance and the rest hold for both).
    std::vector<std::string> noneOverrides;
    for (const std::string& o : overrides) {
        const std::string key = o.substr(0, o.find('='));
        if (key.rfind("sss.", 0) != 0 || sss::methodUsesKey(sss::methodId("none"), key.substr(4)))
            noneOverrides.push_back(o);
    }
    const ExrImage none = render(renderer, folder, scene, "none", noneOverrides, 64, 48);
    for (const auto& method : methods) {
        const ExrImage image = render(renderer, folder, scene, method, overrides, 64, 48);
        double changed = 0.0;
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x) {
                for (const char* c : {"R", "G", "B", "diffuse.R"})
                    ASSERT_TRUE(std::isfinite(image.at(c, x, y))) << scene << " " << method;
                // Non-skin pixels are never written; gaussian-sum re-adds them as Σ_i w_i · colour with
                // Σ_i w_i = 1, exact up to float rounding (1e-6 relative).
                if (image.at("mask.Y", x, y) == 0.0f) {
                    ASSERT_NEAR(image.at("diffuse.G", x, y), none.at("diffuse.G", x, y),
                                1e-6f * std::max(1.0f, std::abs(none.at("diffuse.G", x, y))))
                        << scene << " " << method;
                }
                changed += std::abs(luminance(image, x, y) - luminance(none, x, y));
            }
        EXPECT_GT(changed, 0.0) << scene << " " << method << ": SSS changed nothing";
        EXPECT_GT(image.floats.at("skinlab:sss_radius_mm"), 0.0f) << scene << " " << method;
    }
}
} // namespace

TEST(SssRender, EveryMethodRendersEveryBuiltinScene) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    for (const char* scene : {"builtin:halo-grey-backdrop", "builtin:bleed-true-mask", "builtin:ear", "builtin:head"})
        renderEveryMethod(*renderer, scene);
}

TEST(SssRender, EveryMethodRendersTheScannedHead) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    const char* assets = std::getenv("SKINLAB_ASSETS");
    if (!assets || !*assets) GTEST_SKIP() << "$SKINLAB_ASSETS unset: the scanned head is not available";
    renderEveryMethod(*renderer,
                      (std::filesystem::path(SKINLAB_SOURCE_DIR) / "renderer/scenes/lee-perry-smith.toml").string());
}

// Every screen-space method with every extension switched on at once (and transmittance with its curvature
// option) on every built-in scene and the scanned head.
TEST(SssRender, EveryMethodWithEveryExtensionRendersEveryScene) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    const std::vector<std::string> all{"sss.cbf=true", "sss.lab_weight=0.09", "sss.curvature=reduce-floor",
                                       "transmittance.enabled=true", "transmittance.curvature=true"};
    const std::vector<std::string> methods = renderer::sss::screenSpaceMethodNames();
    std::vector<std::string> scenes{"builtin:halo-grey-backdrop", "builtin:bleed-true-mask", "builtin:ear",
                                    "builtin:head"};
    const char* assets = std::getenv("SKINLAB_ASSETS");
    if (assets && *assets)
        scenes.push_back((std::filesystem::path(SKINLAB_SOURCE_DIR) / "renderer/scenes/lee-perry-smith.toml").string());
    else std::printf("  $SKINLAB_ASSETS unset: the scanned head is skipped\n");
    for (const auto& scene : scenes) renderEveryMethod(*renderer, scene, all, methods);
}

TEST(SssRender, UniformlyLitSkinPlaneKeepsItsMean) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("sss-plane");
    // builtin:bleed made all skin, grey, lit head-on without shadows or environment: a uniformly lit flat plane.
    const std::vector<std::string> plane{
        "materials=[{name = \"*\", skin = true, albedo = [0.5, 0.5, 0.5]}]",
        "lights=[{type = \"directional\", direction = [0.0, 0.0, -1.0], intensity = 2.0, shadow = false}]",
        "environment.radiance=[0.0, 0.0, 0.0]"};
    const ExrImage none = render(*renderer, folder, "builtin:bleed-true-mask", "none", plane, 96, 64);
    for (const auto& method : kMethods) {
        const ExrImage image = render(*renderer, folder, "builtin:bleed-true-mask", method, plane, 96, 64);
        for (const char* c : {"diffuse.R", "diffuse.G", "diffuse.B"}) {
            double before = 0.0, after = 0.0;
            int count = 0;
            for (int y = 8; y < image.height - 8; ++y)
                for (int x = 8; x < image.width - 8; ++x) {
                    if (image.at("mask.Y", x, y) != 1.0f) continue;
                    before += none.at(c, x, y);
                    after += image.at(c, x, y);
                    ++count;
                }
            ASSERT_GT(count, 500);
            EXPECT_NEAR(after / before, 1.0, 0.005) << method << " " << c;
        }
    }
}

TEST(SssRender, FollowSurfaceStopsLightCrossingTheDepthGapOfHalo) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("sss-halo");
    // The backdrop made skin too, so that only the depth gap (200 mm) separates it from the sphere; no shadow, so
    // the backdrop alone is uniformly lit and SSS within it changes nothing: every change on the backdrop is light
    // that crossed the gap.
    const std::vector<std::string> base{
        "materials=[{name = \"*\", skin = true}]",
        "lights=[{type = \"directional\", direction = [0.45, -0.45, -0.77], intensity = 1.2, shadow = false}]"};
    auto crossing = [&](const std::string& method, bool follow) {
        std::vector<std::string> overrides = base;
        // Wide kernel so that it reaches across the silhouette at this small size.
        overrides.push_back("sss.width_mm=12");
        const ExrImage none = render(*renderer, folder, "builtin:halo-grey-backdrop", "none", overrides, 96, 96);
        overrides.push_back(std::string("sss.follow_surface=") + (follow ? "true" : "false")); // not read by none
        const ExrImage image = render(*renderer, folder, "builtin:halo-grey-backdrop", method, overrides, 96, 96);
        float nearest = 1e30f;
        for (float z : image.channels.at("depth.Z")) nearest = std::min(nearest, z);
        double leak = 0.0;
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x)
                if (image.at("depth.Z", x, y) > nearest + 150.0f) // the backdrop (≥ 200 mm behind the sphere's back)
                    leak += std::abs(luminance(image, x, y) - luminance(none, x, y));
        return leak;
    };
    for (const auto& method : kMethods) {
        const double off = crossing(method, false);
        const double on = crossing(method, true);
        EXPECT_GT(off, 0.01) << method << ": no light crossed even without follow-surface";
        EXPECT_LE(on, 0.25 * off) << method;
        std::printf("  %-13s light crossing the gap: %.4g without follow-surface, %.4g with\n", method.c_str(), off,
                    on);
    }
}

} // namespace skinlab::renderer
