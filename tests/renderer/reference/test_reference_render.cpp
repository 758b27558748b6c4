// The object-space reference as a render method (sss.method = "reference", renderer/gl/reference_method.h): real
// renders through Renderer (EGL on llvmpipe here), small images, coarse edge lengths so each render stays short.
#include "../gl/render_test_support.h"
#include "renderer/scene/builtin_geometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

using namespace skinlab::renderer;
using namespace skinlab::renderer::test;

namespace {

struct Rendered {
    ExrImage image;
    nlohmann::json timings;
};

Rendered renderScene(Renderer& renderer, const TempFolder& folder, const std::string& name, const std::string& scene,
                     const std::string& method, std::vector<std::string> overrides, int size = 96) {
    Rendered out;
    out.timings = test::renderToExr(renderer, scene, method, std::move(overrides), size, size, folder / (name + ".exr"))
                      .timingsMs;
    out.image = readExr(folder / (name + ".exr"));
    return out;
}

glm::vec3 diffuseAt(const ExrImage& image, int x, int y) {
    return {image.at("diffuse.R", x, y), image.at("diffuse.G", x, y), image.at("diffuse.B", x, y)};
}

// Uniform light straight onto the bleed patch (+Z faces the camera and the light), no environment, no shadow.
const std::vector<std::string> kHeadOnLight = {
    "lights=[{type = \"directional\", direction = [0.0, 0.0, -1.0], intensity = 1.0, shadow = false}]",
    "environment.radiance=[0.0, 0.0, 0.0]"};

} // namespace

TEST(ReferenceRender, RendersEveryBuiltinScene) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("reference-builtin");
    for (const std::string scene : {"halo-grey-backdrop", "bleed-true-mask", "ear", "head"}) {
        const std::string edge = scene == "head" ? "4" : "3";
        const Rendered reference =
            renderScene(*renderer, folder, scene, "builtin:" + scene, "reference", {"sss.reference_edge_mm=" + edge});
        const Rendered none = renderScene(*renderer, folder, scene + "-none", "builtin:" + scene, "none", {});
        const ExrImage& image = reference.image;
        int skin = 0, changed = 0;
        double nonSkinDifference = 0.0;
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x) {
                const glm::vec3 d = diffuseAt(image, x, y);
                ASSERT_TRUE(std::isfinite(d.r) && std::isfinite(d.g) && std::isfinite(d.b)) << scene;
                const glm::vec3 base = diffuseAt(none.image, x, y);
                if (image.at("mask.Y", x, y) > 0.0f) {
                    ++skin;
                    changed += glm::length(d - base) > 1e-4f * (glm::length(base) + 1e-3f);
                } else {
                    nonSkinDifference = std::max<double>(nonSkinDifference, glm::length(d - base));
                }
            }
        const auto& run = reference.timings.at("reference");
        std::printf("builtin:%s at %s mm: %d samples (%d skin), %.0f sources each; tessellate %.0f ms, bake + read "
                    "back %.0f ms, convolve %.0f ms, sss pass %.0f ms; %d of %d skin pixels changed\n",
                    scene.c_str(), edge.c_str(), run.at("samples").get<int>(), run.at("skin_samples").get<int>(),
                    run.at("sources_per_sample").get<double>(), run.at("tessellate_ms").get<double>(),
                    run.at("bake_readback_ms").get<double>(), run.at("convolve_ms").get<double>(),
                    reference.timings.at("passes_wall").at("sss").get<double>(), changed, skin);
        EXPECT_GT(skin, 100) << scene;
        // SSS softens the lighting almost everywhere on curved skin; the flat, uniformly lit bleed patch stays as
        // it is (the renormalised convolution keeps uniform light unchanged, at the paint borders too).
        if (scene == "bleed-true-mask") EXPECT_EQ(changed, 0) << scene;
        else EXPECT_GT(changed, skin / 4) << scene;
        EXPECT_EQ(nonSkinDifference, 0.0) << scene; // non-skin and background: the main pass's diffuse
        EXPECT_LE(run.at("longest_edge_mm").get<double>(), std::stod(edge)) << scene;
        // Band width of the metrics: the profile's 0.1 % cutoff, 8.04 mm for d'Eon's skin at width 3 mm.
        EXPECT_NEAR(image.floats.at("skinlab:sss_radius_mm"), 8.04f, 0.01f) << scene;
    }
}

TEST(ReferenceRender, NonSkinNeighboursAbsorbOnlyWhenAsked) {
    // builtin:bleed with its true materials under a uniform head-on light: with sss.reference_non_skin = "returns"
    // (the default) the skin stays E·α up to the paint; with "absorbs" the skin next to the paint loses the light
    // its profile carries under the paint — darker there, never brighter, and unchanged far from it.
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("reference-non-skin");
    std::vector<std::string> returns = kHeadOnLight, absorbs = kHeadOnLight;
    returns.push_back("sss.reference_edge_mm=1");
    absorbs.push_back("sss.reference_edge_mm=1");
    absorbs.push_back("sss.reference_non_skin=\"absorbs\"");
    const Rendered kept = renderScene(*renderer, folder, "returns", "builtin:bleed-true-mask", "reference", returns);
    const Rendered lost = renderScene(*renderer, folder, "absorbs", "builtin:bleed-true-mask", "reference", absorbs);
    const Rendered none = renderScene(*renderer, folder, "none", "builtin:bleed-true-mask", "none", kHeadOnLight);
    int skin = 0, darker = 0, brighter = 0;
    double darkest = 1.0;
    for (int y = 0; y < 96; ++y)
        for (int x = 0; x < 96; ++x) {
            if (kept.image.at("mask.Y", x, y) < 0.5f) continue;
            ++skin;
            const double base = none.image.at("diffuse.G", x, y);
            EXPECT_NEAR(kept.image.at("diffuse.G", x, y), base, 1e-4 * base + 1e-6) << x << ", " << y;
            const double ratio = lost.image.at("diffuse.G", x, y) / base;
            darker += ratio < 0.99;
            brighter += ratio > 1.0 + 1e-4;
            darkest = std::min(darkest, ratio);
        }
    std::printf("bleed, absorbing paint: %d of %d skin pixels darker by > 1 %%, darkest at %.3f of E·α\n", darker, skin,
                darkest);
    EXPECT_EQ(brighter, 0);
    EXPECT_GT(darker, 20);       // a ring around both paint squares
    EXPECT_LT(darker, skin / 2); // only near the paint
    EXPECT_LT(darkest, 0.9);
    EXPECT_GT(darkest, 0.3); // at most about half the profile lies under the paint
    const nlohmann::json resolved = nlohmann::json::parse(lost.image.strings.at("skinlab:resolved"));
    EXPECT_EQ(resolved.at("sss").at("reference_non_skin"), "absorbs");
}

TEST(ReferenceRender, ScannedHeadAtACoarseEdge) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    const char* assets = std::getenv("SKINLAB_ASSETS");
    if (!assets || !std::filesystem::exists(std::filesystem::path(assets) / "LeePerrySmith/LeePerrySmith.glb"))
        GTEST_SKIP() << "SKINLAB_ASSETS does not hold LeePerrySmith/ (the scanned head): set it to ../shared/assets";
    TempFolder folder("reference-scanned");
    const std::string scene = std::string(SKINLAB_SOURCE_DIR) + "/renderer/scenes/lee-perry-smith.toml";
    const Rendered reference = renderScene(*renderer, folder, "lps", scene, "reference", {"sss.reference_edge_mm=4"});
    const Rendered none = renderScene(*renderer, folder, "lps-none", scene, "none", {});
    int skin = 0;
    double sumReference = 0.0, sumNone = 0.0;
    for (int y = 0; y < reference.image.height; ++y)
        for (int x = 0; x < reference.image.width; ++x) {
            const glm::vec3 d = diffuseAt(reference.image, x, y);
            ASSERT_TRUE(std::isfinite(d.r) && std::isfinite(d.g) && std::isfinite(d.b));
            if (reference.image.at("mask.Y", x, y) < 1.0f) continue;
            ++skin;
            sumReference += d.r;
            sumNone += diffuseAt(none.image, x, y).r;
        }
    const auto& run = reference.timings.at("reference");
    std::printf("scanned head at 4 mm: %d samples, tessellate %.0f ms, bake %.0f ms, convolve %.0f ms; mean skin red "
                "%.4f (none %.4f) over %d pixels\n",
                run.at("samples").get<int>(), run.at("tessellate_ms").get<double>(),
                run.at("bake_readback_ms").get<double>(), run.at("convolve_ms").get<double>(), sumReference / skin,
                sumNone / skin, skin);
    EXPECT_GT(skin, 500);
    // Same lighting and albedo, redistributed over the surface: the mean over the visible skin stays close.
    EXPECT_NEAR(sumReference / sumNone, 1.0, 0.1);
}

TEST(ReferenceRender, UniformlyLitFlatSkinKeepsItsDiffuse) {
    // builtin:bleed with every material made skin of one albedo, lit head-on: bake + convolution + draw must leave
    // the diffuse as the main pass computed it (the convolution is renormalised; away from the patch's border).
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("reference-flat");
    std::vector<std::string> overrides = kHeadOnLight;
    overrides.push_back("materials=[{name = \"*\", albedo = [0.6, 0.45, 0.4], skin = true}]");
    const Rendered none =
        renderScene(*renderer, folder, "flat-none", "builtin:bleed-true-mask", "none", overrides, 128);
    overrides.push_back("sss.reference_edge_mm=3"); // the reference method's key
    const Rendered reference =
        renderScene(*renderer, folder, "flat", "builtin:bleed-true-mask", "reference", overrides, 128);
    const ExrImage& image = reference.image;
    // Pixels whose 9 × 9 neighbourhood is all skin: away from the patch border (interpolation of the last
    // triangle row against the background is not what this test is about).
    double worst = 0.0;
    int compared = 0;
    for (int y = 4; y < image.height - 4; ++y)
        for (int x = 4; x < image.width - 4; ++x) {
            bool inside = true;
            for (int dy = -4; dy <= 4 && inside; ++dy)
                for (int dx = -4; dx <= 4 && inside; ++dx) inside = image.at("mask.Y", x + dx, y + dy) == 1.0f;
            if (!inside) continue;
            ++compared;
            const glm::vec3 d = diffuseAt(image, x, y), base = diffuseAt(none.image, x, y);
            for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(double(d[c]) / base[c] - 1.0));
        }
    std::printf("flat uniformly lit skin: worst relative change %.2e over %d pixels\n", worst, compared);
    EXPECT_GT(compared, 2000);
    EXPECT_LT(worst, 0.005);
}

TEST(ReferenceRender, ConvergesAsTheEdgeShrinks) {
    // builtin:halo's sphere at edge lengths 2, 1 and 0.5 mm: the image difference between e and e/2 must shrink
    // with e (RMS over the sphere's skin pixels, diffuse, relative to the mean). The sphere's own edges are 0.1–2.8 mm
    // (median 2.0), so the three lengths refine nearly every triangle at each step; sss.width_mm = 0.75 quarters the
    // cutoff radius (2 mm), a sixteenth of the convolution's cost, to keep the 0.5 mm render (232 k samples) short.
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("reference-convergence");
    std::vector<ExrImage> images;
    const char* edges[] = {"2", "1", "0.5"};
    for (const char* edge : edges)
        images.push_back(renderScene(*renderer, folder, std::string("halo-") + edge, "builtin:halo-grey-backdrop",
                                     "reference", {std::string("sss.reference_edge_mm=") + edge, "sss.width_mm=0.75"},
                                     128)
                             .image);
    std::vector<double> differences;
    for (std::size_t k = 0; k + 1 < images.size(); ++k) {
        double squares = 0.0, sum = 0.0;
        int count = 0;
        for (int y = 0; y < images[k].height; ++y)
            for (int x = 0; x < images[k].width; ++x) {
                if (images[k].at("mask.Y", x, y) < 1.0f) continue;
                const glm::vec3 a = diffuseAt(images[k], x, y), b = diffuseAt(images[k + 1], x, y);
                squares += glm::dot(a - b, a - b) / 3.0;
                sum += (b.r + b.g + b.b) / 3.0;
                ++count;
            }
        differences.push_back(std::sqrt(squares / count) / (sum / count));
        std::printf("reference render convergence: edge %s -> %s mm: relative RMS difference %.2e over %d pixels\n",
                    edges[k], edges[k + 1], differences.back(), count);
    }
    EXPECT_LT(differences[1], differences[0]);
    EXPECT_LT(differences[1], 0.01);
}

TEST(ReferenceRender, PaintNeverReachesTheSkin) {
    // builtin:bleed with the paint squares coloured differently (and far brighter): the reference's skin pixels are
    // unchanged, its non-skin pixels equal the main pass's output (method none).
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("reference-skin-only");
    const std::string paint = "materials=[{name = \"paint-dark\", albedo = [0.9, 0.1, 0.05]}, {name = "
                              "\"paint-bright\", albedo = [1.0, 1.0, 1.0]}]";
    const std::vector<std::string> edge = {"sss.reference_edge_mm=3"};
    const Rendered plain = renderScene(*renderer, folder, "plain", "builtin:bleed-true-mask", "reference", edge, 128);
    const Rendered painted =
        renderScene(*renderer, folder, "painted", "builtin:bleed-true-mask", "reference", {edge[0], paint}, 128);
    const Rendered none =
        renderScene(*renderer, folder, "painted-none", "builtin:bleed-true-mask", "none", {paint}, 128);
    int skin = 0, paintPixels = 0, paintChanged = 0;
    double skinDifference = 0.0, paintDifference = 0.0;
    for (int y = 0; y < plain.image.height; ++y)
        for (int x = 0; x < plain.image.width; ++x) {
            const glm::vec3 a = diffuseAt(plain.image, x, y), b = diffuseAt(painted.image, x, y);
            if (plain.image.at("mask.Y", x, y) > 0.0f) {
                ++skin;
                skinDifference = std::max<double>(skinDifference, glm::length(a - b));
            } else {
                paintPixels += plain.image.at("depth.Z", x, y) < 1e30f;
                paintChanged += glm::length(a - b) > 0.01f;
                paintDifference = std::max<double>(paintDifference, glm::length(b - diffuseAt(none.image, x, y)));
            }
        }
    std::printf("skin only: %d skin pixels, max change %.3g; %d of %d paint pixels recoloured; max difference to "
                "method none off skin %.3g\n",
                skin, skinDifference, paintChanged, paintPixels, paintDifference);
    EXPECT_GT(paintChanged, paintPixels / 2); // the paint really changed
    EXPECT_EQ(skinDifference, 0.0);
    EXPECT_EQ(paintDifference, 0.0);
}

TEST(ReferenceRender, DiffuseDoesNotDependOnTheCameraDistance) {
    // Points of builtin:halo's sphere seen from 200 mm and 400 mm away along +Z: the reference's diffuse at the
    // pixels showing them agrees within the interpolation across the pixel footprint (screen-space methods scale
    // their kernels per pixel and differ more; the reference is computed on the surface).
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("reference-view");
    std::vector<ExrImage> images;
    for (const char* distance : {"200", "400"})
        images.push_back(
            renderScene(*renderer, folder, std::string("view-") + distance, "builtin:halo-grey-backdrop", "reference",
                        {"sss.reference_edge_mm=3", "camera.view=explicit", "camera.fov_deg=30",
                         std::string("camera.position=[0.0, 0.0, ") + distance + "]", "camera.target=[0.0, 0.0, 0.0]"},
                        128)
                .image);
    double worst = 0.0;
    for (const float angleDeg : {0.0f, 20.0f, -20.0f, 35.0f}) {
        // A point of the sphere in the horizontal plane, `angleDeg` from the view axis, and the pixel showing it.
        const float a = glm::radians(angleDeg);
        const glm::vec3 point(kHaloSphereRadiusMm * std::sin(a), 0.0f, kHaloSphereRadiusMm * std::cos(a));
        glm::vec3 values[2];
        for (int k = 0; k < 2; ++k) {
            const nlohmann::json camera = nlohmann::json::parse(images[k].strings.at("skinlab:camera"));
            glm::mat4 view, projection;
            for (int i = 0; i < 16; ++i) {
                view[i / 4][i % 4] = camera.at("view")[i].get<float>();
                projection[i / 4][i % 4] = camera.at("projection")[i].get<float>();
            }
            const glm::vec4 clip = projection * view * glm::vec4(point, 1.0f);
            // Bilinear between the four nearest pixel centres (EXR rows top first).
            const float px = (clip.x / clip.w * 0.5f + 0.5f) * float(images[k].width) - 0.5f;
            const float py = (0.5f - clip.y / clip.w * 0.5f) * float(images[k].height) - 0.5f;
            const int x0 = int(std::floor(px)), y0 = int(std::floor(py));
            const float fx = px - float(x0), fy = py - float(y0);
            values[k] =
                glm::mix(glm::mix(diffuseAt(images[k], x0, y0), diffuseAt(images[k], x0 + 1, y0), fx),
                         glm::mix(diffuseAt(images[k], x0, y0 + 1), diffuseAt(images[k], x0 + 1, y0 + 1), fx), fy);
        }
        const double relative = glm::length(values[0] - values[1]) / glm::length(values[1]);
        std::printf("view independence at %+.0f deg: diffuse %.4f %.4f %.4f (200 mm) vs %.4f %.4f %.4f (400 mm), "
                    "relative difference %.2e\n",
                    angleDeg, values[0].r, values[0].g, values[0].b, values[1].r, values[1].g, values[1].b, relative);
        worst = std::max(worst, relative);
    }
    EXPECT_LT(worst, 0.003);
}

TEST(ReferenceRender, RefusesTabulatedProfilesAndTooFineEdges) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("reference-errors");
    try {
        renderScene(*renderer, folder, "fine", "builtin:head", "reference", {"sss.reference_edge_mm=0.05"}, 48);
        FAIL() << "no exception";
    } catch (const skinlab::InputError& e) {
        const std::string message = e.what();
        std::printf("too fine: %s\n", message.c_str());
        EXPECT_EQ(message.find("builtin:head: sss.reference_edge_mm: 0.050000 mm needs more than 8000000 vertices"), 0u)
            << message;
        EXPECT_EQ(message.find('\n'), std::string::npos);
    }
    // A tabulated kernel (.bn: float32 count, then rows r, g, b, offset mm) is a 1-D marginal: no radial form.
    const auto kernel = folder / "five-taps.bn";
    {
        const float values[] = {20.0f, 0.1f, 0.1f, 0.1f, -2.0f, 0.2f, 0.2f, 0.2f, -1.0f, 0.4f, 0.4f,
                                0.4f,  0.0f, 0.2f, 0.2f, 0.2f,  1.0f, 0.1f, 0.1f, 0.1f,  2.0f};
        std::ofstream out(kernel, std::ios::binary);
        out.write(reinterpret_cast<const char*>(values), sizeof(values));
    }
    try {
        renderScene(*renderer, folder, "tabulated", "builtin:halo-grey-backdrop", "reference",
                    {"sss.profile=file:" + kernel.string()}, 48);
        FAIL() << "no exception";
    } catch (const skinlab::InputError& e) {
        const std::string message = e.what();
        std::printf("tabulated: %s\n", message.c_str());
        EXPECT_EQ(message, "builtin:halo-grey-backdrop: sss.profile: 'file:" + kernel.string() +
                               "' has no radial form for the reference method (use deon or burley)");
    }
}

namespace skinlab::renderer {
// The reference's convolution at 3-D distances already carries the light of a lit back face through thin parts,
// so it leaves transmittance (which approximates that in screen space) out: with transmittance on, the screen-space
// pipeline gains light through the ear's fin, the reference's diffuse stays the same (to float rounding).
TEST(ReferenceRender, IgnoresTransmittance) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("reference-transmittance");
    const std::vector<std::string> edge = {"sss.reference_edge_mm=3"};
    const Rendered without = renderScene(*renderer, folder, "without", "builtin:ear", "reference", edge, 96);
    const Rendered with =
        renderScene(*renderer, folder, "with", "builtin:ear", "reference", {edge[0], "transmittance.enabled=true"}, 96);
    const Rendered screen =
        renderScene(*renderer, folder, "screen", "builtin:ear", "none", {"transmittance.enabled=true"}, 96);
    double transmitted = 0.0, difference = 0.0;
    for (int y = 0; y < with.image.height; ++y)
        for (int x = 0; x < with.image.width; ++x) {
            transmitted += screen.image.at("transmittance.R", x, y);
            difference =
                std::max<double>(difference, glm::length(diffuseAt(with.image, x, y) - diffuseAt(without.image, x, y)));
        }
    std::printf("transmittance: screen-space sum of transmittance.R %.4g; reference max change %.3g\n", transmitted,
                difference);
    EXPECT_GT(transmitted, 0.0); // transmittance is really on in this scene
    // Not bit-identical: the draw blends mix(main-pass diffuse, convolved, mask), and the main-pass diffuse does
    // include transmittance; at mask 1 the blend leaves float rounding (≈ 3e-8) of that.
    EXPECT_LT(difference, 1e-6);
}
} // namespace skinlab::renderer
