// Transmittance (Jimenez et al., IEEE CG&A 2010; docs/rendering.md "Transmittance") on builtin:ear, a thin skin fin
// lit from behind by a shadow-casting directional light (label gl; llvmpipe in CI): the fin gets brighter with it
// on, thicker fins transmit less, translucency 1 gives T = 1 exactly (checked per pixel against the formula), no
// transmittance off skin or when disabled, and the transmittance pass adds exactly the AOV (× (1 + c) with
// transmittance.curvature) to the diffuse buffer before the SSS stage.
#include "surface_test_support.h"
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

// builtin:ear at 96 px (the fin fills about half the frame) with a 1024² shadow map: small and fast, and the
// shadow texel (about 0.1 mm) is far below the fin's thickness.
ExrImage renderEar(Renderer& renderer, const TempFolder& folder, const std::string& name,
                   std::vector<std::string> overrides) {
    RenderRequest request;
    request.scene = "builtin:ear";
    // Pixel centres: the AOVs are checked per pixel against their C++ mirrors, which the resolve's averages of
    // nonlinear quantities would not follow (anti-aliasing: test_antialiasing.cpp).
    request.overrides = {"render.antialiasing=none", "shadow.resolution=1024"};
    for (auto& o : overrides) request.overrides.push_back(std::move(o));
    request.width = 96;
    request.height = 96;
    request.exrPath = folder / (name + ".exr");
    renderer.render(request);
    return readExr(request.exrPath);
}

double skinMean(const ExrImage& image, const std::string& channel) {
    const std::vector<float>& mask = image.channels.at("mask.Y");
    const std::vector<float>& values = image.channels.at(channel);
    double sum = 0.0;
    int count = 0;
    for (std::size_t p = 0; p < mask.size(); ++p)
        if (mask[p] > 0.0f) {
            sum += values[p];
            ++count;
        }
    return count > 0 ? sum / count : 0.0;
}

float maxAbs(const ExrImage& image, const std::string& channel) {
    float largest = 0.0f;
    for (float v : image.channels.at(channel)) largest = std::max(largest, std::abs(v));
    return largest;
}

constexpr const char* kRgb[] = {"R", "G", "B"};

TEST(Transmittance, BackLitFinIsBrighterWithItOnAndTheDiffuseGainsExactlyTheAov) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("transmittance-on-off");
    const ExrImage off = renderEar(*renderer, folder, "off", {});
    // Translucency 0.75: s = 2.5 mm × 16.5 (1 − 0.75) / 3 = 3.4 (the demo's scale, docs/methods.md), where d'Eon's
    // red tail still transmits a few per cent.
    const ExrImage on =
        renderEar(*renderer, folder, "on", {"transmittance.enabled=true", "transmittance.translucency=0.75"});
    for (const char* c : kRgb) EXPECT_EQ(maxAbs(off, std::string("transmittance.") + c), 0.0f) << c;

    const double offMean = skinMean(off, "diffuse.R");
    const double onMean = skinMean(on, "diffuse.R");
    const double transmittedMean = skinMean(on, "transmittance.R");
    std::printf("builtin:ear (2.5 mm, translucency 0.75): skin diffuse.R mean %.5f off, %.5f on (+%.1f %%); "
                "transmittance.R mean %.5f\n",
                offMean, onMean, 100.0 * (onMean / offMean - 1.0), transmittedMean);
    EXPECT_GT(onMean, offMean * 1.05); // the back light reaches the front of the thin fin
    EXPECT_GT(transmittedMean, 0.0);
    // Red travels farthest through skin (d'Eon's widest lobes are red).
    EXPECT_GT(skinMean(on, "transmittance.R"), skinMean(on, "transmittance.G"));
    EXPECT_GT(skinMean(on, "transmittance.G"), skinMean(on, "transmittance.B"));

    // Method none: diffuse = main pass + transmittance, so on − off is the AOV, pixel by pixel.
    int changed = 0;
    for (const char* c : kRgb) {
        const std::vector<float>& a = on.channels.at(std::string("diffuse.") + c);
        const std::vector<float>& b = off.channels.at(std::string("diffuse.") + c);
        const std::vector<float>& t = on.channels.at(std::string("transmittance.") + c);
        for (std::size_t p = 0; p < a.size(); ++p) {
            ASSERT_NEAR(a[p] - b[p], t[p], 1e-6f + 1e-5f * a[p]) << c << " pixel " << p;
            changed += t[p] > 0.0f;
        }
    }
    EXPECT_GT(changed, 500);
}

TEST(Transmittance, DisabledLeavesTheDiffuseUnchangedWhateverTheTranslucency) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("transmittance-disabled");
    const ExrImage a = renderEar(*renderer, folder, "a", {"transmittance.translucency=0.5"});
    const ExrImage b =
        renderEar(*renderer, folder, "b", {"transmittance.translucency=1.0", "transmittance.curvature=true"});
    for (const char* c : kRgb) {
        EXPECT_EQ(a.channels.at(std::string("diffuse.") + c), b.channels.at(std::string("diffuse.") + c)) << c;
        EXPECT_EQ(maxAbs(b, std::string("transmittance.") + c), 0.0f) << c;
    }
}

TEST(Transmittance, ThickerFinsTransmitLess) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("transmittance-thickness");
    double previous = 0.0;
    bool first = true;
    for (const double thicknessMm : {1.0, 2.5, 5.0}) {
        const ExrImage image = renderEar(*renderer, folder, "t" + std::to_string(thicknessMm),
                                         {"model.thickness_mm=" + std::to_string(thicknessMm),
                                          "transmittance.enabled=true", "transmittance.translucency=0.8"});
        const double mean = skinMean(image, "transmittance.R");
        std::printf("builtin:ear thickness %.1f mm, translucency 0.8: skin transmittance.R mean %.5f\n", thicknessMm,
                    mean);
        EXPECT_GT(mean, 0.0);
        if (!first) {
            EXPECT_LT(mean, previous * 0.8) << thicknessMm << " mm";
        }
        previous = mean;
        first = false;
    }
}

TEST(Transmittance, FullTranslucencyGivesUnitTransmittancePerPixel) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("transmittance-unit");
    // Exposure +1 EV: the AOV carries exposure like every radiance AOV.
    const ExrImage image =
        renderEar(*renderer, folder, "unit",
                  {"transmittance.enabled=true", "transmittance.translucency=1.0", "render.exposure_ev=1"});
    // The back light of builtin:ear (renderer/scenes/builtin/ear.toml); the front fill casts no shadow and so
    // transmits nothing.
    const glm::vec3 toLight = -glm::normalize(glm::vec3(0.15f, -0.2f, 0.97f));
    const glm::vec3 radiance = glm::vec3(1.0f, 0.95f, 0.88f) * 3.0f;
    const float exposure = 2.0f;
    int checked = 0;
    float largestError = 0.0f;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            const float mask = image.at("mask.Y", x, y);
            const glm::vec3 normal{image.at("geonormal.X", x, y), image.at("geonormal.Y", x, y),
                                   image.at("geonormal.Z", x, y)};
            // s = 0 ⇒ T = 1: exposure · albedo · L_c · saturate(0.3 + L·(−N)) · mask.
            const float facing = std::clamp(0.3f + glm::dot(toLight, -normal), 0.0f, 1.0f);
            for (int c = 0; c < 3; ++c) {
                const std::string channel = kRgb[c];
                const float expected = exposure * image.at("albedo." + channel, x, y) * radiance[c] * facing * mask;
                const float actual = image.at("transmittance." + channel, x, y);
                ASSERT_NEAR(actual, expected, 1e-5f + 1e-4f * expected) << channel << " at " << x << "," << y;
                largestError = std::max(largestError, std::abs(actual - expected));
            }
            if (mask > 0.0f && facing > 0.0f) ++checked;
        }
    std::printf("translucency 1: %d back-lit skin pixels, largest |transmittance - formula| %.2g\n", checked,
                largestError);
    EXPECT_GT(checked, 500);
}

TEST(Transmittance, NoneOffSkin) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("transmittance-non-skin");
    // The same back-lit fin with its material marked non-skin: lit, shadow-mapped, but no transmittance.
    const ExrImage image = renderEar(*renderer, folder, "paint",
                                     {"materials=[{name = \"skin\", skin = false}]", "transmittance.enabled=true",
                                      "transmittance.translucency=1.0"});
    EXPECT_EQ(skinMean(image, "mask.Y"), 0.0);
    EXPECT_GT(maxAbs(image, "diffuse.R"), 0.01f);
    for (const char* c : kRgb) EXPECT_EQ(maxAbs(image, std::string("transmittance.") + c), 0.0f) << c;
}

TEST(Transmittance, CurvatureOptionScalesTheAddedLightByOnePlusNormalisedCurvature) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("transmittance-curvature");
    const ExrImage off = renderEar(*renderer, folder, "off", {});
    const ExrImage on =
        renderEar(*renderer, folder, "curvature", {"transmittance.enabled=true", "transmittance.curvature=true"});
    const float mmPerUnit = on.floats.at("skinlab:mm_per_unit");
    int curved = 0;
    for (int y = 0; y < on.height; ++y)
        for (int x = 0; x < on.width; ++x) {
            const float c = sss::normalisedCurvature(on.at("curvature.Y", x, y), mmPerUnit);
            if (c > 0.1f && on.at("transmittance.R", x, y) > 0.0f) ++curved;
            for (const char* channel : kRgb) {
                const float added =
                    on.at(std::string("diffuse.") + channel, x, y) - off.at(std::string("diffuse.") + channel, x, y);
                const float expected =
                    on.at(std::string("transmittance.") + channel, x, y) * sss::transmittanceCurvatureScale(c);
                ASSERT_NEAR(added, expected, 1e-6f + 1e-5f * on.at(std::string("diffuse.") + channel, x, y))
                    << channel << " at " << x << "," << y;
            }
        }
    std::printf("transmittance.curvature: %d transmitting pixels with normalised curvature > 0.1 (the fin's rim)\n",
                curved);
    EXPECT_GT(curved, 20); // the rounded rim of the fin is tightly curved
}

// transmittance.curvature_form = "thesis": the profile widened inside the exponent, s / (1 + 2c), in the main pass
// (c uncapped, from the thesis' screen-space curvature). T(s) falls with s, so every pixel transmits at least as
// much as without the curvature term, more on the fin's curved rim, and the diffuse gains exactly the AOV (no
// × (1 + c) afterwards).
TEST(Transmittance, ThesisCurvatureFormWidensTheProfileInsideTheExponent) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("transmittance-curvature-thesis");
    const ExrImage off = renderEar(*renderer, folder, "off", {});
    const ExrImage plain =
        renderEar(*renderer, folder, "plain", {"transmittance.enabled=true", "transmittance.translucency=0.75"});
    const ExrImage thesis = renderEar(*renderer, folder, "thesis",
                                      {"transmittance.enabled=true", "transmittance.translucency=0.75",
                                       "transmittance.curvature=true", "transmittance.curvature_form=thesis"});
    int brighter = 0;
    for (int y = 0; y < thesis.height; ++y)
        for (int x = 0; x < thesis.width; ++x)
            for (const char* channel : kRgb) {
                const std::string t = std::string("transmittance.") + channel;
                ASSERT_GE(thesis.at(t, x, y), plain.at(t, x, y) * (1.0f - 1e-5f)) << channel << " at " << x << "," << y;
                if (std::string(channel) == "R" && thesis.at(t, x, y) > plain.at(t, x, y) * 1.01f) ++brighter;
                const std::string d = std::string("diffuse.") + channel;
                ASSERT_NEAR(thesis.at(d, x, y) - off.at(d, x, y), thesis.at(t, x, y),
                            1e-6f + 1e-5f * thesis.at(d, x, y));
            }
    std::printf("transmittance.curvature_form = thesis: %d pixels transmit > 1 %% more red than without curvature\n",
                brighter);
    EXPECT_GT(brighter, 20);
}

} // namespace
} // namespace skinlab::renderer
