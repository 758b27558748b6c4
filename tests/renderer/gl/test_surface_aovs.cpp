// The surface-AOV pass (renderer/gl/surface_aov_pass.h; label gl, llvmpipe in CI): curvature.Y ≈ 1/r on the
// sphere of builtin:halo at two resolutions and two distances, ≈ 0 on the flat patch of builtin:bleed, 0 off skin;
// aux.Y per pixel against the C++ mirror of Mikkelsen's auxiliary image (renderer/sss/extension_weights.h) with
// positions reconstructed here from the depth AOV, ≈ albedo grey at the sphere's centre and growing towards its
// silhouette.
#include "surface_test_support.h"
#include "renderer/scene/builtin_geometry.h"
#include "renderer/sss/extension_weights.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/glm.hpp>

namespace skinlab::renderer {
namespace {

using test::ExrImage;
using test::readExr;
using test::TempFolder;

ExrImage renderScene(Renderer& renderer, const TempFolder& folder, const std::string& scene, int size,
                     std::vector<std::string> overrides = {}) {
    RenderRequest request;
    request.scene = scene;
    // Pixel centres: the AOVs are checked per pixel against their C++ mirrors, which the resolve's averages of
    // nonlinear quantities would not follow (anti-aliasing: test_antialiasing.cpp).
    request.overrides = {"render.antialiasing=none", "shadow.resolution=256"}; // shadows play no part here
    for (auto& o : overrides) request.overrides.push_back(std::move(o));
    request.width = size;
    request.height = size;
    request.exrPath =
        folder / (scene.substr(8) + std::to_string(size) + std::to_string(request.overrides.size()) + ".exr");
    renderer.render(request);
    return readExr(request.exrPath);
}

double median(std::vector<double> values) {
    if (values.empty()) return 0.0;
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2), values.end());
    return values[values.size() / 2];
}

TEST(SurfaceAovs, SphereCurvatureIsOneOverItsRadius) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("curvature-sphere");
    const double expected = 1.0 / kHaloSphereRadiusMm; // 1/world unit (1 unit = 1 mm)
    struct Variant {
        int size;
        const char* view;
    };
    // Two resolutions and two distances: the measure is in 1/world unit, independent of the pixel scale.
    for (const Variant variant : {Variant{128, "mid"}, Variant{64, "mid"}, Variant{96, "far"}}) {
        const ExrImage image = renderScene(*renderer, folder, "builtin:halo-grey-backdrop", variant.size,
                                           {std::string("camera.view=") + variant.view});
        std::vector<double> interior;
        for (const auto& [x, y] : test::interiorSkinPixels(image, 4)) interior.push_back(image.at("curvature.Y", x, y));
        const double measured = median(interior);
        std::printf("builtin:halo sphere (r = %.0f mm), %d px, view %s: median curvature %.6f /mm over %zu interior "
                    "pixels (1/r = %.6f, ratio %.4f)\n",
                    kHaloSphereRadiusMm, variant.size, variant.view, measured, interior.size(), expected,
                    measured / expected);
        ASSERT_GT(interior.size(), 100u);
        EXPECT_NEAR(measured / expected, 1.0, 0.10);
        // Non-negative everywhere, zero off skin (backdrop, background).
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x) {
                ASSERT_GE(image.at("curvature.Y", x, y), 0.0f);
                if (image.at("mask.Y", x, y) == 0.0f) {
                    ASSERT_EQ(image.at("curvature.Y", x, y), 0.0f) << x << "," << y;
                }
            }
    }
}

TEST(SurfaceAovs, FlatPatchCurvatureIsNearZero) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("curvature-plane");
    const ExrImage image = renderScene(*renderer, folder, "builtin:bleed-true-mask", 128);
    const auto interior = test::interiorSkinPixels(image, 4);
    ASSERT_GT(interior.size(), 1000u);
    float largest = 0.0f;
    for (const auto& [x, y] : interior) largest = std::max(largest, std::abs(image.at("curvature.Y", x, y)));
    std::printf("builtin:bleed flat patch, 128 px: largest |curvature| %.3g /mm over %zu interior pixels "
                "(bound 0.1/40 = %.3g)\n",
                largest, interior.size(), 0.1 / kHaloSphereRadiusMm);
    EXPECT_LT(largest, 0.1f / kHaloSphereRadiusMm);
}

TEST(SurfaceAovs, AuxiliaryImageMatchesTheCppMirrorAndGrowsTowardsTheSilhouette) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("aux-sphere");
    const ExrImage image = renderScene(*renderer, folder, "builtin:halo-grey-backdrop", 128);
    const test::ExrCamera camera = test::exrCamera(image);
    const glm::mat3 viewFromWorld(camera.view);
    int checked = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            if (image.at("mask.Y", x, y) == 0.0f) {
                ASSERT_EQ(image.at("aux.Y", x, y), 0.0f) << x << "," << y;
                continue;
            }
            const glm::vec3 position = test::viewPositionAt(image, camera, x, y);
            const glm::vec3 normal =
                glm::normalize(viewFromWorld * glm::vec3(image.at("geonormal.X", x, y), image.at("geonormal.Y", x, y),
                                                         image.at("geonormal.Z", x, y)));
            const float grey =
                (image.at("albedo.R", x, y) + image.at("albedo.G", x, y) + image.at("albedo.B", x, y)) / 3.0f;
            const float expected = sss::auxiliaryValue(position, normal, grey);
            ASSERT_NEAR(image.at("aux.Y", x, y), expected, 1e-3f * expected + 1e-5f) << x << "," << y;
            ++checked;
        }
    EXPECT_GT(checked, 1000);

    // The sphere's centre (the origin) seen head-on: cos φ_i = cos φ_j = 1, F = 1 × grey. Then outwards along the
    // row through the centre F = cos φ_i / cos φ_j grows as the surface turns away from the viewer.
    const glm::vec4 clip = camera.projection * camera.view * glm::vec4(0, 0, 0, 1);
    const int centreX = static_cast<int>(std::floor((clip.x / clip.w * 0.5f + 0.5f) * static_cast<float>(image.width)));
    const int centreY =
        static_cast<int>(std::floor((0.5f - clip.y / clip.w * 0.5f) * static_cast<float>(image.height)));
    const float grey = (image.at("albedo.R", centreX, centreY) + image.at("albedo.G", centreX, centreY) +
                        image.at("albedo.B", centreX, centreY)) /
                       3.0f;
    const float centre = image.at("aux.Y", centreX, centreY);
    std::printf("aux.Y at the sphere centre pixel (%d, %d): %.5f, albedo grey %.5f (ratio %.4f)\n", centreX, centreY,
                centre, grey, centre / grey);
    EXPECT_NEAR(centre / grey, 1.0f, 0.02f);
    int edge = centreX;
    while (edge + 1 < image.width && image.at("mask.Y", edge + 1, centreY) > 0.0f) ++edge;
    const int radiusPixels = edge - centreX;
    ASSERT_GT(radiusPixels, 20);
    float previous = centre;
    for (const float fraction : {0.4f, 0.7f, 0.9f}) {
        const int x = centreX + static_cast<int>(fraction * static_cast<float>(radiusPixels));
        const float value = image.at("aux.Y", x, centreY);
        std::printf("  aux.Y at %.0f %% of the radius: %.5f\n", 100.0 * fraction, value);
        EXPECT_GT(value, previous);
        previous = value;
    }
}

// sss.curvature_measure = "screen": the thesis' screen-space measure, scaled so that a sphere seen face-on reads 1/r
// at its centre. For a sphere it grows towards the silhouette as (1/cos θ + cos θ) / 2 along the row through the
// centre (θ the angle of the normal from the view axis): × 1.36 at 90 % of the radius. The 3-D measure stays 1/r.
TEST(SurfaceAovs, ScreenSpaceCurvatureGrowsTowardsTheSilhouette) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("curvature-screen");
    const ExrImage normal = renderScene(*renderer, folder, "builtin:halo-grey-backdrop", 160);
    const ExrImage screen =
        renderScene(*renderer, folder, "builtin:halo-grey-backdrop", 160, {"sss.curvature_measure=screen"});
    const test::ExrCamera camera = test::exrCamera(screen);
    const glm::vec4 clip = camera.projection * camera.view * glm::vec4(0, 0, 0, 1);
    const int centreX =
        static_cast<int>(std::floor((clip.x / clip.w * 0.5f + 0.5f) * static_cast<float>(screen.width)));
    const int centreY =
        static_cast<int>(std::floor((0.5f - clip.y / clip.w * 0.5f) * static_cast<float>(screen.height)));
    int edge = centreX;
    while (edge + 1 < screen.width && screen.at("mask.Y", edge + 1, centreY) > 0.0f) ++edge;
    const int radiusPixels = edge - centreX;
    ASSERT_GT(radiusPixels, 20);
    const double inverseRadius = 1.0 / kHaloSphereRadiusMm;
    const double screenCentre = screen.at("curvature.Y", centreX, centreY) / inverseRadius;
    const double normalCentre = normal.at("curvature.Y", centreX, centreY) / inverseRadius;
    const int outer = centreX + static_cast<int>(0.9f * static_cast<float>(radiusPixels));
    const double screenOuter = screen.at("curvature.Y", outer, centreY) / inverseRadius;
    const double normalOuter = normal.at("curvature.Y", outer, centreY) / inverseRadius;
    std::printf("builtin:halo sphere, 160 px, curvature × r: centre screen %.3f / normal %.3f; at 90 %% of the radius "
                "screen %.3f / normal %.3f\n",
                screenCentre, normalCentre, screenOuter, normalOuter);
    EXPECT_NEAR(screenCentre, 1.0, 0.1);
    EXPECT_NEAR(normalOuter, 1.0, 0.1);
    EXPECT_GT(screenOuter, 1.2 * screenCentre);
    EXPECT_GT(screenOuter, 1.2 * normalOuter);
}

} // namespace
} // namespace skinlab::renderer
