// The GL pipeline against known answers (label gl; llvmpipe in CI): a Lambert plane lit head-on, the
// specular lobe of thesis Eq. 4.5 per pixel against its C++ mirror, the irradiance of a constant environment,
// shadows, tone mappers + sRGB encoding against their C++ mirrors, the EXR layout, determinism.
#include "render_test_support.h"
#include "common/error.h"
#include "renderer/output/display_output.h"
#include "renderer/scene/texture.h"
#include "renderer/shading/specular_brdf.h"
#include "renderer/shading/tone_mappers.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_inverse.hpp>
#include <nlohmann/json.hpp>

namespace skinlab::renderer {
namespace {

using test::ExrImage;
using test::readExr;
using test::TempFolder;

// builtin:bleed (a flat skin patch at z = 0 facing +Z, 1 unit = 1 mm) with a grey skin albedo of 0.5, one
// head-on directional light of L_c = 2 and no environment: the analytic scene of these tests.
RenderRequest lambertPlane(const std::filesystem::path& exr, std::vector<std::string> extra = {}) {
    RenderRequest request;
    request.scene = "builtin:bleed-true-mask";
    request.overrides = {
        "materials=[{name = \"skin\", albedo = [0.5, 0.5, 0.5], glossiness = 0.5, specular_intensity = 1.0}]",
        "lights=[{type = \"directional\", direction = [0.0, 0.0, -1.0], intensity = 2.0, shadow = false}]",
        "environment.radiance=[0.0, 0.0, 0.0]", "tone_map.operator=linear"};
    for (auto& e : extra) request.overrides.push_back(e);
    request.width = 64;
    request.height = 48;
    request.exrPath = exr;
    return request;
}

int countSkinPixels(const ExrImage& image) {
    int count = 0;
    for (float m : image.channels.at("mask.Y")) count += m == 1.0f;
    return count;
}

TEST(RenderPipeline, LambertPlaneLitHeadOnHasTheAnalyticRadiance) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("lambert");
    renderer->render(lambertPlane(folder / "plane.exr"));
    const ExrImage image = readExr(folder / "plane.exr");
    ASSERT_GT(countSkinPixels(image), 500);
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            if (image.at("mask.Y", x, y) != 1.0f) continue;
            // Radiance of a Lambertian surface facing a light of L_c: albedo * L_c * (n.l) = 0.5 * 2 * 1.
            for (const char* c : {"diffuse.R", "diffuse.G", "diffuse.B"})
                ASSERT_NEAR(image.at(c, x, y), 1.0f, 1e-5f) << c << " at " << x << "," << y;
            ASSERT_NEAR(image.at("albedo.G", x, y), 0.5f, 1e-6f);
            ASSERT_NEAR(image.at("normal.Z", x, y), 1.0f, 1e-5f);
            ASSERT_NEAR(image.at("geonormal.Z", x, y), 1.0f, 1e-5f);
        }
}

TEST(RenderPipeline, SpecularMatchesEquation45PerPixel) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("specular");
    renderer->render(lambertPlane(folder / "plane.exr"));
    const ExrImage image = readExr(folder / "plane.exr");
    const nlohmann::json camera = nlohmann::json::parse(image.strings.at("skinlab:camera"));
    glm::mat4 view;
    for (int i = 0; i < 16; ++i) view[i / 4][i % 4] = camera["view"][static_cast<std::size_t>(i)].get<float>();
    const glm::mat4 worldFromView = glm::inverse(view);
    const glm::vec3 cameraPosition{camera["position"][0].get<float>(), camera["position"][1].get<float>(),
                                   camera["position"][2].get<float>()};
    const float tanHalf = std::tan(glm::radians(camera["fov_y_deg"].get<float>()) * 0.5f);
    const float aspect = static_cast<float>(image.width) / static_cast<float>(image.height);
    int checked = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            if (image.at("mask.Y", x, y) != 1.0f) continue;
            // The pixel centre's world position from the linear depth AOV (view-space z = -depth).
            const float ndcX = 2.0f * (static_cast<float>(x) + 0.5f) / static_cast<float>(image.width) - 1.0f;
            const float ndcY = 1.0f - 2.0f * (static_cast<float>(y) + 0.5f) / static_cast<float>(image.height);
            const float depth = image.at("depth.Z", x, y);
            const glm::vec3 viewPoint{ndcX * tanHalf * aspect * depth, ndcY * tanHalf * depth, -depth};
            const glm::vec3 world = glm::vec3(worldFromView * glm::vec4(viewPoint, 1.0f));
            ASSERT_NEAR(world.z, 0.0f, 1e-3f); // the patch lies in z = 0
            const glm::vec3 toViewer = glm::normalize(cameraPosition - world);
            const float expected = 2.0f * specularEq45({0, 0, 1}, {0, 0, 1}, toViewer, 0.5f);
            ASSERT_NEAR(image.at("specular.G", x, y), expected, 1e-3f * expected + 1e-6f) << x << "," << y;
            ++checked;
        }
    EXPECT_GT(checked, 500);
}

TEST(RenderPipeline, SpecularBrdfMirrorAgainstHandComputedValues) {
    // Head-on (n = l = v = h): (alpha + 2) / 8 * 1 * F0 * 1; glossiness 0.5 → alpha = 8192 / 32 = 256.
    EXPECT_NEAR(specularEq45({0, 0, 1}, {0, 0, 1}, {0, 0, 1}, 0.5f), 258.0f / 8.0f * 0.028f, 1e-5f);
    // Glossiness 0 → alpha = 0: a constant lobe 2/8 * F * (n.l).
    const glm::vec3 l = glm::normalize(glm::vec3(0, 1, 1));
    const glm::vec3 v = glm::normalize(glm::vec3(0, -1, 1)); // mirror direction: h = n, l.h = cos 45°
    const float f = 0.028f + 0.972f * std::pow(1.0f - std::sqrt(0.5f), 5.0f);
    EXPECT_NEAR(specularEq45({0, 0, 1}, l, v, 0.0f), 0.25f * f * std::sqrt(0.5f), 1e-6f);
    // Same geometry, alpha = 256: (n.h)^alpha = 1 at the mirror direction.
    EXPECT_NEAR(specularEq45({0, 0, 1}, l, v, 0.5f), 258.0f / 8.0f * f * std::sqrt(0.5f), 1e-4f);
    // Light below the horizon: no specular.
    EXPECT_EQ(specularEq45({0, 0, 1}, {0, 0, -1}, {0, 0, 1}, 0.5f), 0.0f);
    // Schlick at grazing and normal incidence.
    EXPECT_NEAR(fresnelSchlick(0.028f, 1.0f), 0.028f, 1e-7f);
    EXPECT_NEAR(fresnelSchlick(0.028f, 0.0f), 1.0f, 1e-7f);
}

TEST(RenderPipeline, ConstantEnvironmentGivesAlbedoTimesRadiance) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("environment");
    // No lights; a uniform environment of radiance L: irradiance E = pi L, so a Lambertian surface of albedo
    // a reflects a E / pi = a L whatever its orientation (9 SH coefficients represent a constant exactly).
    renderer->render(lambertPlane(folder / "env.exr", {"lights=[]", "environment.radiance=[0.3, 0.6, 0.9]"}));
    const ExrImage image = readExr(folder / "env.exr");
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            if (image.at("mask.Y", x, y) != 1.0f) continue;
            ASSERT_NEAR(image.at("diffuse.R", x, y), 0.15f, 1e-3f * 0.15f);
            ASSERT_NEAR(image.at("diffuse.G", x, y), 0.30f, 1e-3f * 0.30f);
            ASSERT_NEAR(image.at("diffuse.B", x, y), 0.45f, 1e-3f * 0.45f);
            ASSERT_EQ(image.at("specular.G", x, y), 0.0f); // specular comes from lights only
        }
}

// environment.irradiance = "exact" against "sh9": a dim sky of radiance 0.1 with a small sun of 1000 straight behind
// the plane (−Z, the environment image's centre). The plane, facing +Z, sees only the sky: E = π · 0.1, so its albedo
// 0.5 reflects 0.05. The irradiance map gives that (within the quadrature of the sky's texels, 1 %); nine SH
// coefficients ring the sun's light onto the far hemisphere (its clamped-cosine approximation at 180° is 1/16 of the
// peak), several times the sky's light.
TEST(RenderPipeline, ExactEnvironmentIrradianceLeavesASunBehindThePlaneOut) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("irradiance");
    const int width = 64, height = 32;
    std::vector<float> pixels(static_cast<std::size_t>(width * height * 3), 0.1f);
    for (int y = 15; y < 17; ++y)
        for (int x = 31; x < 33; ++x)
            for (int c = 0; c < 3; ++c) pixels[static_cast<std::size_t>((y * width + x) * 3 + c)] = 1000.0f;
    const std::string hdr = (folder / "sun-behind.exr").string();
    {
        auto out = OIIO::ImageOutput::create(hdr);
        ASSERT_TRUE(out && out->open(hdr, OIIO::ImageSpec(width, height, 3, OIIO::TypeDesc::FLOAT)));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
        out->close();
    }
    // builtin:bleed's flat patch facing +Z, all of it skin of albedo 0.5, lit by the environment file alone.
    const std::filesystem::path scene = folder / "plane.toml";
    std::ofstream(scene) << "mm_per_unit = 1.0\n[model]\nsource = \"builtin:bleed\"\n"
                         << "[[materials]]\nname = \"*\"\nalbedo = [0.5, 0.5, 0.5]\nskin = true\n"
                         << "[camera]\nview = \"mid\"\n[tone_map]\noperator = \"linear\"\n"
                         << "[environment]\nfile = \"" << hdr << "\"\nbackground = \"color\"\n";
    for (const char* irradiance : {"sh9", "exact"}) {
        RenderRequest request;
        request.scene = scene.string();
        request.overrides = {std::string("environment.irradiance=\"") + irradiance + "\""};
        request.width = 64;
        request.height = 48;
        request.exrPath = folder / (std::string(irradiance) + ".exr");
        renderer->render(request);
    }
    const ExrImage sh9 = readExr(folder / "sh9.exr");
    const ExrImage map = readExr(folder / "exact.exr");
    ASSERT_GT(countSkinPixels(map), 500);
    for (int y = 0; y < map.height; ++y)
        for (int x = 0; x < map.width; ++x) {
            if (map.at("mask.Y", x, y) != 1.0f) continue;
            ASSERT_NEAR(map.at("diffuse.G", x, y), 0.05f, 0.01f * 0.05f) << x << "," << y;
            ASSERT_GT(sh9.at("diffuse.G", x, y), 2.0f * 0.05f) << x << "," << y;
        }
}

TEST(RenderPipeline, ExposureScalesBeautyAndAovsByPowersOfTwo) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("exposure");
    renderer->render(lambertPlane(folder / "a.exr"));
    renderer->render(lambertPlane(folder / "b.exr", {"render.exposure_ev=-2"}));
    const ExrImage a = readExr(folder / "a.exr");
    const ExrImage b = readExr(folder / "b.exr");
    for (std::size_t p = 0; p < a.channels.at("R").size(); ++p) {
        ASSERT_NEAR(b.channels.at("R")[p], 0.25f * a.channels.at("R")[p], 1e-6f);
        ASSERT_NEAR(b.channels.at("specular.R")[p], 0.25f * a.channels.at("specular.R")[p], 1e-6f);
    }
}

// render.window renders the window's pixels of the whole frame: with pscbf (view rays from the shifted principal
// point, kernels in millimetres at the frame's focal length) every pixel a kernel's reach inside the window equals
// the frame's; only near the window's edges, where the blur lacks the light from outside, may they differ.
TEST(RenderPipeline, WindowEqualsTheFramesPixelsAwayFromItsEdges) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("window");
    const std::vector<std::string> common = {"camera.view=\"close\"", "shadow.resolution=512"};
    test::renderToExr(*renderer, "builtin:head", "pscbf", common, 192, 192, folder / "whole.exr");
    std::vector<std::string> windowed = common;
    windowed.push_back("render.window={ x = 60, y = 70, width = 64, height = 48 }");
    test::renderToExr(*renderer, "builtin:head", "pscbf", windowed, 192, 192, folder / "window.exr");
    const ExrImage whole = readExr(folder / "whole.exr");
    const ExrImage part = readExr(folder / "window.exr");
    ASSERT_EQ(part.width, 64);
    ASSERT_EQ(part.height, 48);
    EXPECT_EQ(part.strings.at("skinlab:window"), "60 70 64 48");
    EXPECT_EQ(part.floats.at("skinlab:f_px"), whole.floats.at("skinlab:f_px"));
    const int margin = 12;
    double largest = 0.0;
    for (int y = margin; y < part.height - margin; ++y)
        for (int x = margin; x < part.width - margin; ++x)
            for (const char* channel : {"R", "G", "B", "diffuse.R", "diffuse.G", "diffuse.B", "depth.Z", "mask.Y"}) {
                const double a = part.at(channel, x, y), b = whole.at(channel, 60 + x, 70 + y);
                largest = std::max(largest, std::fabs(a - b) / std::max(1e-3, std::fabs(b)));
            }
    EXPECT_LT(largest, 2e-3);
}

TEST(RenderPipeline, ShadowsDarkenTheBackdropBehindTheSphere) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("shadow");
    RenderRequest request;
    request.scene = "builtin:halo-grey-backdrop";
    request.width = 96;
    request.height = 96;
    request.exrPath = folder / "lit.exr";
    // The key light of halo.toml, without and with its shadow (--set replaces the whole array of lights).
    const std::string light =
        "lights=[{type = \"directional\", direction = [0.45, -0.45, -0.77], intensity = 1.2, shadow = ";
    request.overrides = {light + "false}]"};
    renderer->render(request);
    request.exrPath = folder / "shadowed.exr";
    request.overrides = {light + "true}]"};
    renderer->render(request);
    const ExrImage lit = readExr(folder / "lit.exr");
    const ExrImage shadowed = readExr(folder / "shadowed.exr");
    int darkened = 0, backdrop = 0;
    for (std::size_t p = 0; p < lit.channels.at("R").size(); ++p) {
        if (lit.channels.at("mask.Y")[p] != 0.0f || !std::isfinite(lit.channels.at("depth.Z")[p])) continue;
        ++backdrop;
        const float before = lit.channels.at("diffuse.G")[p];
        const float after = shadowed.channels.at("diffuse.G")[p];
        ASSERT_LE(after, before * (1.0f + 1e-5f) + 1e-7f); // a shadow never brightens
        darkened += after < 0.5f * before;
    }
    EXPECT_GT(backdrop, 1000);
    EXPECT_GT(darkened, backdrop / 50) << "expected the sphere's shadow on the backdrop";
}

TEST(RenderPipeline, ExrLayoutChannelsAndMetadata) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("layout");
    RenderRequest request;
    request.scene = "builtin:halo-grey-backdrop";
    request.width = 64;
    request.height = 64;
    request.exrPath = folder / "halo.exr";
    const RenderResult result = renderer->render(request);
    const ExrImage image = readExr(request.exrPath);
    for (const char* channel : {"R",
                                "G",
                                "B",
                                "diffuse.R",
                                "diffuse.G",
                                "diffuse.B",
                                "specular.R",
                                "specular.G",
                                "specular.B",
                                "albedo.R",
                                "albedo.G",
                                "albedo.B",
                                "depth.Z",
                                "normal.X",
                                "normal.Y",
                                "normal.Z",
                                "geonormal.X",
                                "geonormal.Y",
                                "geonormal.Z",
                                "mask.Y",
                                "transmittance.R",
                                "transmittance.G",
                                "transmittance.B",
                                "aux.Y",
                                "curvature.Y"})
        EXPECT_TRUE(image.channels.count(channel)) << channel;
    EXPECT_EQ(image.channels.size(), 25u);
    EXPECT_EQ(nlohmann::json::parse(image.strings.at("skinlab:resolved")), result.resolved);
    EXPECT_EQ(image.strings.at("skinlab:gl_renderer"), renderer->glRenderer());
    EXPECT_EQ(image.strings.at("skinlab:gl_version"), renderer->glVersion());
    EXPECT_FALSE(image.strings.at("skinlab:version").empty());
    EXPECT_NEAR(image.floats.at("skinlab:f_px"), 32.0f / std::tan(glm::radians(15.0f)), 1e-3f);
    EXPECT_EQ(image.floats.at("skinlab:mm_per_unit"), 1.0f);
    EXPECT_TRUE(image.floats.count("skinlab:sss_radius_mm"));
    EXPECT_FALSE(image.strings.count("DateTime")); // determinism: no timestamps
    int skin = 0;
    for (std::size_t p = 0; p < image.channels.at("R").size(); ++p) {
        const float mask = image.channels.at("mask.Y")[p];
        skin += mask > 0.0f;
        // beauty = diffuse (after SSS) + specular
        EXPECT_NEAR(image.channels.at("G")[p], image.channels.at("diffuse.G")[p] + image.channels.at("specular.G")[p],
                    1e-6f * (1.0f + image.channels.at("G")[p]));
        EXPECT_GE(mask, 0.0f);
        EXPECT_LE(mask, 1.0f);
        const float depth = image.channels.at("depth.Z")[p];
        EXPECT_TRUE(std::isinf(depth) || (depth > 0.0f && depth < 2000.0f));
    }
    EXPECT_GT(skin, 200);
    // Timings: every pass, the first GL timer query discarded, GPU ≤ wall per pass.
    for (const char* pass : {"shadow", "main", "background", "sss", "add_specular", "tone_map"}) {
        ASSERT_TRUE(result.timingsMs["passes"].contains(pass)) << pass;
        EXPECT_GE(result.timingsMs["passes"][pass].get<double>(), 0.0);
        EXPECT_LE(result.timingsMs["passes"][pass].get<double>(),
                  result.timingsMs["passes_wall"][pass].get<double>() * 1.05 + 0.05);
    }
}

TEST(RenderPipeline, BackgroundPixelsHaveInfiniteDepthAndZeroMask) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("background");
    RenderRequest request;
    request.scene = "builtin:ear";
    request.width = 64;
    request.height = 64;
    request.exrPath = folder / "ear.exr";
    renderer->render(request);
    const ExrImage image = readExr(request.exrPath);
    // The corner is background in the ear scene (a fin in empty space): +inf depth, mask 0, background colour
    // 0.01 (ear.toml) in the beauty.
    EXPECT_TRUE(std::isinf(image.at("depth.Z", 0, 0)));
    EXPECT_EQ(image.at("mask.Y", 0, 0), 0.0f);
    EXPECT_NEAR(image.at("R", 0, 0), 0.01f, 1e-6f);
}

TEST(RenderPipeline, ToneMappersAndSrgbEncodingMatchTheirCppMirrors) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("tonemap");
    for (const char* toneMapper : {"linear", "exponential", "reinhard", "reinhard-rgb", "filmic"}) {
        RenderRequest request;
        request.scene = "builtin:head";
        request.width = 48;
        request.height = 48;
        request.overrides = {std::string("tone_map.operator=") + toneMapper, "tone_map.exponential_k=1.7"};
        request.exrPath = folder / (std::string(toneMapper) + ".exr");
        request.pngPath = folder / (std::string(toneMapper) + ".png");
        renderer->render(request);
        const ExrImage image = readExr(request.exrPath);
        int width = 0, height = 0;
        const std::vector<unsigned char> png = test::readPng(request.pngPath, width, height);
        ASSERT_EQ(width, 48);
        std::vector<float> display;
        const std::size_t pixels = image.channels.at("R").size();
        std::vector<float> rgb;
        for (std::size_t p = 0; p < pixels; ++p)
            for (const char* c : {"R", "G", "B"}) rgb.push_back(image.channels.at(c)[p]);
        // reinhard: the key 0.18 over the log-average luminance of the beauty (the EXR's R, G, B).
        const float scale = static_cast<float>(kReinhardDefaultKey / reinhardLogAverage(rgb.data(), pixels, 3));
        for (std::size_t p = 0; p < pixels; ++p) {
            if (std::string(toneMapper) == "reinhard") {
                float y[3];
                toneMapReinhard(&rgb[p * 3], scale, y);
                display.insert(display.end(), y, y + 3);
            } else {
                for (int c = 0; c < 3; ++c) display.push_back(toneMap(rgb[p * 3 + c], toneMapper, 1.7f));
            }
        }
        const std::vector<std::uint8_t> expected = encodeDisplaySrgb8(display);
        int maxDifference = 0;
        for (std::size_t i = 0; i < png.size(); ++i)
            maxDifference = std::max(maxDifference, std::abs(static_cast<int>(png[i]) - static_cast<int>(expected[i])));
        // One 8-bit code: GPU exp/pow and the C++ ones may round a value on either side of a code boundary.
        EXPECT_LE(maxDifference, 1) << toneMapper;
    }
}

TEST(DisplayTransform, SrgbThroughOpenColorIOAgainstKnownValues) {
    // IEC 61966-2-1: 0.0031308 ↔ 0.04045 (the linear segment's end), 0.18 → 0.4613561, 0.5 ← 0.2140411.
    EXPECT_NEAR(linearToSrgb(0.0031308f), 0.04045f, 1e-5f);
    EXPECT_NEAR(linearToSrgb(0.18f), 0.4613561f, 1e-5f);
    EXPECT_NEAR(srgbToLinear(0.5f), 0.2140411f, 1e-5f);
    EXPECT_NEAR(linearToSrgb(srgbToLinear(0.73f)), 0.73f, 1e-5f);
    // 8-bit display codes: 0.18 → 0.4613561 * 255 = 117.65 → 118; 0.8 → 0.9063318 * 255 = 231.1 → 231.
    const std::vector<std::uint8_t> codes = encodeDisplaySrgb8({0.0f, 0.18f, 0.8f, 1.0f, 2.0f, -1.0f});
    EXPECT_EQ(std::vector<int>(codes.begin(), codes.end()), (std::vector<int>{0, 118, 231, 255, 255, 0}));
}

TEST(ToneMappers, KnownValues) {
    EXPECT_FLOAT_EQ(toneMap(0.25f, "linear"), 0.25f);
    EXPECT_FLOAT_EQ(toneMap(3.0f, "linear"), 1.0f);
    EXPECT_FLOAT_EQ(toneMap(1.0f, "reinhard-rgb"), 0.5f);
    // Reinhard et al. 2002, Eqs. 1–3 on luminance. Eq. 1: the log-average of luminances 1 and 4 is
    // √((1 + δ)(4 + δ)) ≈ 2 (δ = 1e-4).
    const float two[6] = {1.0f, 1.0f, 1.0f, 4.0f, 4.0f, 4.0f};
    EXPECT_NEAR(reinhardLogAverage(two, 2, 3), std::sqrt((1.0 + 1e-4) * (4.0 + 1e-4)), 1e-6);
    // Eqs. 2–3 with a / L̄ = 1: grey 1 → L = 1 → 0.5, as per channel; saturated red (1, 0, 0) has L_w = 0.2126, so
    // it maps to 1 / 1.2126 = 0.8247 and stays pure red, where the per-channel form gives 0.5 (darker).
    float y[3];
    const float grey[3] = {1.0f, 1.0f, 1.0f}, red[3] = {1.0f, 0.0f, 0.0f}, skin[3] = {2.0f, 1.0f, 0.6f};
    toneMapReinhard(grey, 1.0f, y);
    EXPECT_NEAR(y[0], 0.5f, 1e-6f);
    EXPECT_NEAR(y[2], 0.5f, 1e-6f);
    toneMapReinhard(red, 1.0f, y);
    EXPECT_NEAR(y[0], 1.0f / 1.2126f, 1e-6f);
    EXPECT_EQ(y[1], 0.0f);
    // A bright skin colour keeps its channel ratios (2 : 1 : 0.6) under the luminance form; per channel it does not.
    toneMapReinhard(skin, 0.5f, y);
    EXPECT_NEAR(y[0] / y[1], 2.0f, 1e-5f);
    EXPECT_NEAR(y[2] / y[1], 0.6f, 1e-5f);
    EXPECT_LT(toneMap(2.0f, "reinhard-rgb") / toneMap(1.0f, "reinhard-rgb"), 1.34f); // (2/3) / (1/2)
    // The key a scales the image before the curve: a = 0.36 on L̄ = 0.18 doubles the scaled luminance.
    toneMapReinhard(grey, 0.36f / 0.18f, y);
    EXPECT_NEAR(y[0], 2.0f / 3.0f, 1e-6f);
    EXPECT_NEAR(toneMap(1.0f, "exponential", 2.0f), 1.0f - std::exp(-2.0f), 1e-7f);
    EXPECT_NEAR(toneMap(5.6f, "filmic"), 1.0f, 1e-6f); // hable(2 * W / 2) / hable(W): white maps to 1
    EXPECT_NEAR(toneMap(0.0f, "filmic"), 0.0f, 1e-7f); // hable(0) = DE/DF - E/F = 0 up to float rounding
}

TEST(RenderPipeline, ScannedHeadRendersWithItsMapsAndEnvironment) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    const char* assets = std::getenv("SKINLAB_ASSETS");
    if (!assets || !std::filesystem::exists(std::filesystem::path(assets) / "LeePerrySmith/LeePerrySmith.glb"))
        GTEST_SKIP() << "SKINLAB_ASSETS does not hold LeePerrySmith/ (the scanned head): set it to ../shared/assets";
    TempFolder folder("scanned");
    RenderRequest request;
    request.scene = std::string(SKINLAB_SOURCE_DIR) + "/renderer/scenes/lee-perry-smith.toml";
    request.assetsDir = assets;
    request.width = 128;
    request.height = 128;
    request.exrPath = folder / "lps.exr";
    request.pngPath = folder / "lps.png";
    renderer->render(request);
    const ExrImage image = readExr(request.exrPath);
    EXPECT_NEAR(image.floats.at("skinlab:mm_per_unit"), 47.9f, 1e-4f);
    int skin = 0, mapped = 0, background = 0;
    double albedoSum = 0, albedoSquares = 0, specularMax = 0;
    for (std::size_t p = 0; p < image.channels.at("R").size(); ++p) {
        ASSERT_TRUE(std::isfinite(image.channels.at("R")[p]));
        if (image.channels.at("mask.Y")[p] == 0.0f) {
            // Background from the HDR environment: not black.
            background += image.channels.at("G")[p] > 0.0f;
            continue;
        }
        ++skin;
        const double a = image.channels.at("albedo.R")[p];
        albedoSum += a;
        albedoSquares += a * a;
        specularMax = std::max(specularMax, static_cast<double>(image.channels.at("specular.G")[p]));
        const glm::vec3 n{image.channels.at("normal.X")[p], image.channels.at("normal.Y")[p],
                          image.channels.at("normal.Z")[p]};
        const glm::vec3 g{image.channels.at("geonormal.X")[p], image.channels.at("geonormal.Y")[p],
                          image.channels.at("geonormal.Z")[p]};
        mapped += glm::dot(n, g) < 0.9999f; // the map is smooth ("SmoothUV"): small deviations
    }
    ASSERT_GT(skin, 128 * 128 / 10);
    const double mean = albedoSum / skin;
    EXPECT_GT(std::sqrt(albedoSquares / skin - mean * mean), 0.02) << "albedo map not applied";
    EXPECT_GT(mapped, skin / 4) << "normal map not applied"; // measured: about half the skin pixels
    EXPECT_GT(specularMax, 0.0);
    EXPECT_GT(background, 100);
}

TEST(RenderPipeline, SameInputsGiveByteIdenticalFiles) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("determinism");
    RenderRequest request;
    request.scene = "builtin:head";
    request.width = 96;
    request.height = 80;
    for (const char* name : {"a", "b"}) {
        request.exrPath = folder / (std::string(name) + ".exr");
        request.pngPath = folder / (std::string(name) + ".png");
        renderer->render(request);
    }
    EXPECT_EQ(test::readText(folder / "a.exr"), test::readText(folder / "b.exr"));
    EXPECT_EQ(test::readText(folder / "a.png"), test::readText(folder / "b.png"));
}

// renderDisplay (live tuning) has no Blender: the methods Blender renders are refused with a one-line error naming
// the method, never shown as the rasterizer's frame without their SSS.
TEST(RenderPipeline, DisplayRefusesTheMethodsBlenderRenders) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    for (const std::string method : {"pathtraced", "eevee"}) {
        RenderRequest request;
        request.scene = "builtin:halo";
        request.method = method;
        request.width = 32;
        request.height = 24;
        try {
            renderer->renderDisplay(request);
            ADD_FAILURE() << method << ": rendered without Blender";
        } catch (const InputError& e) {
            const std::string message = e.what();
            EXPECT_NE(message.find("sss.method: '" + method + "'"), std::string::npos) << message;
            EXPECT_EQ(message.find('\n'), std::string::npos) << message;
        }
    }
}

} // namespace
} // namespace skinlab::renderer
