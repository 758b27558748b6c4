// Mikkelsen's pseudo-separable cross-bilateral filter as a GL method (sss.method = "pscbf"; label gl, llvmpipe in
// CI, small images). Two kinds of test share the renderer's EGL context:
//  - whole renders through the public API: every builtin scene (and the scanned head with $SKINLAB_ASSETS), a
//    uniformly lit plane keeps its mean, the depth weight stops light crossing builtin:halo's gap;
//  - the SSS stage on synthetic textures (exact impulses, planes of known tilt): isotropy on a 16:9 image, the
//    per-axis tilt correction, the spike, energy, and the extensions' plumbing.
#include "../gl/render_test_support.h"
#include "renderer/gl/gl_resources.h"
#include "renderer/gl/pscbf_method.h"
#include "renderer/gl/shader_library.h"
#include "renderer/gl/sss_stage.h"
#include "renderer/renderer.h"
#include "renderer/sss/cpu_blur.h"
#include "renderer/sss/kernel.h"
#include "renderer/sss/pscbf_cpu.h"
#include "renderer/sss/pscbf_kernel.h"
#include "renderer/sss/sss_params.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <gtest/gtest.h>
#include <limits>
#include <memory>
#include <numbers>

namespace skinlab::renderer {
namespace {

using test::ExrImage;
using test::readExr;
using test::TempFolder;

// --- whole renders ------------------------------------------------------------------------------------------

ExrImage render(Renderer& renderer, const TempFolder& folder, const std::string& scene, const std::string& method,
                std::vector<std::string> overrides, int width, int height) {
    test::renderToExr(renderer, scene, method, std::move(overrides), width, height, folder / (method + ".exr"));
    return readExr(folder / (method + ".exr"));
}

double luminance(const ExrImage& image, int x, int y) { return test::diffuseLuminance(image, x, y); }

// Renders `scene` with none and pscbf at 64×48: finite output, non-skin pixels untouched, skin changed, support
// radius r_max = 4.5 mm at the default width.
void renderScene(Renderer& renderer, const std::string& scene) {
    TempFolder folder("pscbf-scene");
    const ExrImage none = render(renderer, folder, scene, "none", {}, 64, 48);
    const ExrImage image = render(renderer, folder, scene, "pscbf", {}, 64, 48);
    double changed = 0.0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            for (const char* c : {"R", "G", "B", "diffuse.R", "diffuse.G", "diffuse.B"})
                ASSERT_TRUE(std::isfinite(image.at(c, x, y))) << scene << " " << c << " at " << x << "," << y;
            // Non-skin pixels are copied through both passes (the same float, bit for bit).
            if (image.at("mask.Y", x, y) == 0.0f) {
                for (const char* c : {"diffuse.R", "diffuse.G", "diffuse.B"})
                    ASSERT_EQ(image.at(c, x, y), none.at(c, x, y)) << scene << " " << c << " at " << x << "," << y;
            }
            changed += std::abs(luminance(image, x, y) - luminance(none, x, y));
        }
    EXPECT_GT(changed, 0.0) << scene << ": pscbf changed nothing";
    EXPECT_FLOAT_EQ(image.floats.at("skinlab:sss_radius_mm"), 4.5f) << scene;
    std::printf("  %s: summed |ΔY| on the image %.4g\n", scene.c_str(), changed);
}

// --- the SSS stage on synthetic textures -------------------------------------------------------------------

// One frame of SSS stage inputs, CPU side; rows bottom first (GL order), view = identity (world = view space).
struct SyntheticFrame {
    int width = 160;
    int height = 90; // 16:9
    float focalLengthPixels = 300.0f;
    float mmPerUnit = 1.0f;
    std::vector<std::array<float, 4>> diffuse; // rgb, a = skin mask
    std::vector<float> depth;                  // world units
    std::vector<std::array<float, 4>> normal;  // world = view space, xyz unit
    std::vector<std::array<float, 4>> albedo;
    std::vector<float> aux;
    std::vector<float> curvature;

    size_t index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }
    // The ray from the pixel's surface point to the camera, scaled to unit depth (pscbf_blur.frag's w).
    std::array<double, 3> ray(int x, int y) const {
        return {(0.5 * width - (x + 0.5)) / focalLengthPixels, (0.5 * height - (y + 0.5)) / focalLengthPixels, 1.0};
    }
};

// A skin plane through the point seen at pixel `anchor` at depth `anchorDepth`, with view-space normal n (towards
// the camera), every pixel's depth exact along its own ray; black diffuse, grey albedo.
SyntheticFrame plane(std::array<double, 3> n, double anchorDepth, std::array<int, 2> anchor) {
    SyntheticFrame frame;
    const size_t pixels = size_t(frame.width) * size_t(frame.height);
    frame.diffuse.assign(pixels, {0.0f, 0.0f, 0.0f, 1.0f});
    frame.depth.resize(pixels);
    frame.normal.assign(pixels, {float(n[0]), float(n[1]), float(n[2]), 0.0f});
    frame.albedo.assign(pixels, {0.5f, 0.5f, 0.5f, 1.0f});
    frame.aux.assign(pixels, 1.0f);
    frame.curvature.assign(pixels, 0.0f);
    auto dot = [&](std::array<double, 3> w) { return n[0] * w[0] + n[1] * w[1] + n[2] * w[2]; };
    const double anchorDot = dot(frame.ray(anchor[0], anchor[1]));
    for (int y = 0; y < frame.height; ++y)
        for (int x = 0; x < frame.width; ++x)
            frame.depth[frame.index(x, y)] = float(anchorDepth * anchorDot / dot(frame.ray(x, y)));
    return frame;
}

struct StageFixture {
    std::unique_ptr<gl::ShaderLibrary> shaders;
    std::unique_ptr<gl::SssStage> stage;
};

// The SSS stage on the renderer's context (current on this thread once the renderer exists).
StageFixture& stageFixture() {
    static StageFixture fixture;
    if (!fixture.stage) {
        fixture.shaders = std::make_unique<gl::ShaderLibrary>();
        fixture.stage = std::make_unique<gl::SssStage>(*fixture.shaders);
    }
    return fixture;
}

sss::SssParams pscbfParams() {
    sss::SssParams params;
    params.method = sss::methodId("pscbf");
    params.samples = sss::kPscbfSamples; // Mikkelsen's 13 taps per axis
    return params;
}

// Runs the SSS stage on the frame; returns rgba per pixel (rows bottom first).
std::vector<std::array<float, 4>> runStage(const SyntheticFrame& frame, const sss::SssParams& params) {
    const int w = frame.width, h = frame.height;
    auto upload = [&](GLenum format, GLenum layout, const void* data) {
        gl::Texture texture = gl::createTexture2D(format, w, h);
        glTextureSubImage2D(texture.get(), 0, 0, 0, w, h, layout, GL_FLOAT, data);
        return texture;
    };
    std::vector<float> mask(frame.diffuse.size());
    for (size_t i = 0; i < mask.size(); ++i) mask[i] = frame.diffuse[i][3];
    const gl::Texture diffuse = upload(GL_RGBA32F, GL_RGBA, frame.diffuse.data());
    const gl::Texture depth = upload(GL_R32F, GL_RED, frame.depth.data());
    const gl::Texture normal = upload(GL_RGBA32F, GL_RGBA, frame.normal.data());
    const gl::Texture albedo = upload(GL_RGBA32F, GL_RGBA, frame.albedo.data());
    const gl::Texture aux = upload(GL_R32F, GL_RED, frame.aux.data());
    const gl::Texture curvature = upload(GL_R32F, GL_RED, frame.curvature.data());
    const gl::Texture skinMask = upload(GL_R32F, GL_RED, mask.data());
    const gl::Texture output = gl::createTexture2D(GL_RGBA32F, w, h);
    gl::SssStageInputs inputs;
    inputs.diffuse = diffuse.get();
    inputs.linearDepth = depth.get();
    inputs.albedo = albedo.get();
    inputs.skinMask = skinMask.get();
    inputs.normal = normal.get();
    inputs.geometricNormal = normal.get();
    inputs.aux = aux.get();
    inputs.curvature = curvature.get();
    inputs.width = w;
    inputs.height = h;
    inputs.focalLengthPixels = frame.focalLengthPixels;
    inputs.mmPerUnit = frame.mmPerUnit;
    gl::SssStageSettings settings;
    settings.sss = params;
    stageFixture().stage->run(inputs, settings, output.get());
    std::vector<std::array<float, 4>> out(frame.diffuse.size());
    glGetTextureImage(output.get(), 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(out.size() * sizeof(out[0])),
                      out.data());
    gl::checkGl("pscbf test readback");
    return out;
}

// Spread of the broad (blurred) part of an impulse response around the impulse, per axis, in pixels:
// √(Σ b·d² / Σ b) with b = output − spike · input (the spike sits at d = 0 and would only dilute the moments).
struct Spread {
    double x = 0.0;
    double y = 0.0;
    double energy = 0.0; // Σ output (the impulse has energy 1)
};

Spread impulseSpread(const SyntheticFrame& frame, const std::vector<std::array<float, 4>>& out, std::array<int, 2> at,
                     int channel, double spike) {
    double sum = 0.0, xx = 0.0, yy = 0.0, energy = 0.0;
    for (int y = 0; y < frame.height; ++y)
        for (int x = 0; x < frame.width; ++x) {
            const double value = out[frame.index(x, y)][channel];
            energy += value;
            const double broad = value - spike * frame.diffuse[frame.index(x, y)][channel];
            sum += broad;
            xx += broad * (x - at[0]) * (x - at[0]);
            yy += broad * (y - at[1]) * (y - at[1]);
        }
    return {std::sqrt(xx / sum), std::sqrt(yy / sum), energy};
}

// A plane facing the camera at 4 pixels per mm (the red taps then reach 18 pixels), an impulse at the centre.
constexpr double kFacingDepth = 75.0; // f_px / (mm_per_unit · 4 px/mm)
const std::array<int, 2> kCentre{80, 45};

SyntheticFrame impulseOnPlane(std::array<double, 3> normal) {
    SyntheticFrame frame = plane(normal, kFacingDepth, kCentre);
    frame.diffuse[frame.index(kCentre[0], kCentre[1])] = {1.0f, 1.0f, 1.0f, 1.0f};
    return frame;
}

} // namespace

TEST(PscbfRender, RendersEveryBuiltinScene) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    for (const char* scene : {"builtin:halo-grey-backdrop", "builtin:bleed-true-mask", "builtin:ear", "builtin:head"})
        renderScene(*renderer, scene);
}

TEST(PscbfRender, RendersTheScannedHead) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    const char* assets = std::getenv("SKINLAB_ASSETS");
    if (!assets || !*assets) GTEST_SKIP() << "$SKINLAB_ASSETS unset: the scanned head is not available";
    renderScene(*renderer,
                (std::filesystem::path(SKINLAB_SOURCE_DIR) / "renderer/scenes/lee-perry-smith.toml").string());
}

TEST(PscbfRender, UniformlyLitSkinPlaneKeepsItsMean) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("pscbf-plane");
    // builtin:bleed made all skin, grey, lit head-on without shadows or environment: a uniformly lit flat plane
    // (the set-up of test_sss_render's UniformlyLitSkinPlaneKeepsItsMean).
    const std::vector<std::string> plane{
        "materials=[{name = \"*\", skin = true, albedo = [0.5, 0.5, 0.5]}]",
        "lights=[{type = \"directional\", direction = [0.0, 0.0, -1.0], intensity = 2.0, shadow = false}]",
        "environment.radiance=[0.0, 0.0, 0.0]"};
    const ExrImage none = render(*renderer, folder, "builtin:bleed-true-mask", "none", plane, 96, 64);
    const ExrImage image = render(*renderer, folder, "builtin:bleed-true-mask", "pscbf", plane, 96, 64);
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
        EXPECT_NEAR(after / before, 1.0, 0.005) << c;
        std::printf("  %s: mean after / before = %.6f over %d pixels\n", c, after / before, count);
    }
}

TEST(PscbfRender, DepthWeightStopsLightCrossingTheDepthGapOfHalo) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("pscbf-halo");
    // The backdrop made skin too, so that only the depth gap (200 mm) separates it from the sphere; no shadow, so
    // the backdrop alone is uniformly lit and SSS within it changes nothing: every change on the backdrop is light
    // that crossed the gap. Wide kernel (width_mm 12: r_max 18 mm) so that it reaches across the silhouette.
    auto crossing = [&](const std::string& method, bool follow) {
        std::vector<std::string> overrides{
            "materials=[{name = \"*\", skin = true}]",
            "lights=[{type = \"directional\", direction = [0.45, -0.45, -0.77], intensity = 1.2, shadow = false}]",
            "sss.width_mm=12"};
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
    const double separableOff = crossing("separable", false);
    const double pscbfOff = crossing("pscbf", false);
    const double pscbf = crossing("pscbf", true);
    EXPECT_GT(separableOff, 0.01) << "no light crossed the gap even without follow-surface";
    EXPECT_GT(pscbfOff, 0.01) << "no light crossed the gap with pscbf's depth weight off";
    // The depth weight at a 200 mm step is exp(−200² / (2 · 6.07²)) ≈ 0 (σ_R at width 12): nothing crosses but
    // float rounding.
    EXPECT_LE(pscbf, 0.01 * separableOff);
    std::printf("  light crossing the gap: separable without follow-surface %.4g, pscbf without its depth weight "
                "%.4g, pscbf %.4g\n",
                separableOff, pscbfOff, pscbf);
}

TEST(PscbfStage, MatchesTheCpuMirrorOnATestImage) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    // 16:9 image: a plane facing the camera on the left, a plane turned 50° about y 30 mm behind on the right, a
    // non-skin rectangle, a band of half-skin mask, background (+inf depth, mask 0) at the right edge; a smooth
    // pattern with a few sharp bright features; albedo, F and curvature varying so every extension has work to do.
    SyntheticFrame frame = plane({0.0, 0.0, 1.0}, 120.0, kCentre);
    frame.width = 96;
    frame.height = 54;
    const size_t pixels = size_t(frame.width) * size_t(frame.height);
    frame.diffuse.resize(pixels);
    frame.depth.resize(pixels);
    frame.normal.resize(pixels);
    frame.albedo.resize(pixels);
    frame.aux.resize(pixels);
    frame.curvature.resize(pixels);
    const double tilt = 50.0 * std::numbers::pi / 180.0;
    for (int y = 0; y < frame.height; ++y)
        for (int x = 0; x < frame.width; ++x) {
            const size_t i = frame.index(x, y);
            float mask = 1.0f;
            frame.depth[i] = 120.0f;
            frame.normal[i] = {0.0f, 0.0f, 1.0f, 0.0f};
            if (x >= 40) {
                frame.normal[i] = {float(std::sin(tilt)), 0.0f, float(std::cos(tilt)), 0.0f};
                frame.depth[i] = 150.0f + 0.4f * float(x - 40);
            }
            if (x >= 60 && x < 70 && y >= 20 && y < 34) mask = 0.0f;
            if (y >= 45 && y < 48) mask = 0.5f;
            if (x >= 86) {
                mask = 0.0f;
                frame.depth[i] = std::numeric_limits<float>::infinity();
            }
            frame.diffuse[i] = {0.6f + 0.4f * std::sin(0.31f * x) * std::cos(0.17f * y),
                                0.4f + 0.3f * std::cos(0.23f * x + 0.11f * y), 0.3f + 0.2f * std::sin(0.07f * x * y),
                                mask};
            if ((x * 7 + y * 13) % 97 == 0) frame.diffuse[i] = {4.0f, 3.0f, 2.0f, mask};
            frame.albedo[i] = {0.5f + 0.3f * std::sin(0.2f * x), 0.4f, 0.3f + 0.2f * std::cos(0.3f * y), 1.0f};
            frame.aux[i] = 1.0f + 0.05f * float(x % 11);
            frame.curvature[i] = 0.002f * float(y % 30);
        }
    sss::SurfaceBuffers surface;
    surface.width = frame.width;
    surface.height = frame.height;
    surface.depth = frame.depth;
    surface.focalLengthPixels = frame.focalLengthPixels;
    surface.mmPerUnit = frame.mmPerUnit;
    std::vector<sss::Rgb> diffuse(pixels), normals(pixels);
    for (size_t i = 0; i < pixels; ++i) {
        surface.mask.push_back(frame.diffuse[i][3]);
        surface.albedo.push_back({frame.albedo[i][0], frame.albedo[i][1], frame.albedo[i][2]});
        diffuse[i] = {frame.diffuse[i][0], frame.diffuse[i][1], frame.diffuse[i][2]};
        normals[i] = {frame.normal[i][0], frame.normal[i][1], frame.normal[i][2]};
    }
    surface.aux = frame.aux;
    surface.curvature = frame.curvature;

    struct Variant {
        const char* name;
        sss::SssParams params;
    };
    std::vector<Variant> variants{{"13 taps", pscbfParams()}};
    variants.push_back({"21 taps, width 6 mm", pscbfParams()});
    variants.back().params.samples = 21;
    variants.back().params.widthMm = 6.0;
    variants.push_back({"no depth weight", pscbfParams()});
    variants.back().params.followSurface = false;
    variants.push_back({"cbf + lab_weight + reduce-floor", pscbfParams()});
    variants.back().params.cbf = true;
    variants.back().params.labWeight = 0.09;
    variants.back().params.curvature = "reduce-floor";
    for (const auto& variant : variants) {
        sss::PscbfCpuInputs inputs;
        inputs.surface = &surface;
        inputs.viewNormal = normals;
        inputs.depthWeight = variant.params.followSurface;
        const glm::dvec3 sigma = gl::PscbfMethod::depthSigmaMm(variant.params);
        inputs.depthSigmaMm = {float(sigma.x), float(sigma.y), float(sigma.z)};
        inputs.extensions = sss::blurSettingsFromParams(variant.params);
        const auto cpu = sss::applyPscbf(inputs, diffuse, sss::makeKernel(variant.params));
        const auto gpu = runStage(frame, variant.params);
        float worst = 0.0f;
        for (size_t i = 0; i < pixels; ++i)
            for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(cpu[i][c] - gpu[i][c]));
        // Colours up to 4; both sides compute in float in the same order, what differs is fused multiply-adds and
        // the GPU's exp/pow/sqrt, a few ulps each (measured ≤ 2e-6 on llvmpipe): 1e-4 leaves room for other
        // drivers while any change of the method (a weight, a clamp, the spike) moves pixels by far more.
        EXPECT_LT(worst, 1e-4f) << variant.name;
        std::printf("  %-32s largest |GPU − CPU| %.3g\n", variant.name, worst);
    }
}

TEST(PscbfStage, ImpulseSpreadsEquallyOnBothAxesOfA16By9Image) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    const SyntheticFrame frame = impulseOnPlane({0.0, 0.0, 1.0});
    const auto out = runStage(frame, pscbfParams());
    const auto& spike = sss::mikkelsenSkinProfile().spike;
    for (int c = 0; c < 3; ++c) {
        const Spread spread = impulseSpread(frame, out, kCentre, c, spike[c]);
        // Same pixel scale on both axes: equal up to float rounding (the taps are the same on both axes).
        EXPECT_NEAR(spread.x / spread.y, 1.0, 0.02) << "channel " << c;
        // A convolution on a uniform skin plane: the impulse's energy is kept (float sums over 14 400 pixels).
        EXPECT_NEAR(spread.energy, 1.0, 1e-4) << "channel " << c;
        std::printf("  channel %d: spread x %.3f px, y %.3f px, ratio %.4f, energy %.6f\n", c, spread.x, spread.y,
                    spread.x / spread.y, spread.energy);
    }
}

TEST(PscbfStage, TiltCorrectionShrinksTheSpreadAlongTheTiltedAxis) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    const SyntheticFrame facing = impulseOnPlane({0.0, 0.0, 1.0});
    const Spread reference = impulseSpread(facing, runStage(facing, pscbfParams()), kCentre, 0, 0.15);
    for (const double degrees : {30.0, 60.0}) {
        const double phi = degrees * std::numbers::pi / 180.0;
        // Turned about the view-space y axis (the normal in the XZ plane) and about x (normal in the YZ plane).
        const SyntheticFrame aboutY = impulseOnPlane({std::sin(phi), 0.0, std::cos(phi)});
        const SyntheticFrame aboutX = impulseOnPlane({0.0, std::sin(phi), std::cos(phi)});
        const Spread y = impulseSpread(aboutY, runStage(aboutY, pscbfParams()), kCentre, 0, 0.15);
        const Spread x = impulseSpread(aboutX, runStage(aboutX, pscbfParams()), kCentre, 0, 0.15);
        // Red spread ≈ 6 px: the linear interpolation between texels adds ≈ 1/6 px² to both variances, so the
        // measured ratio exceeds cos φ by < 0.5 %; the plane's depth varies across the kernel (≈ 8 % at 60°), which
        // the per-pixel footprint follows; 0.03 covers both.
        EXPECT_NEAR(y.x / reference.x, std::cos(phi), 0.03) << degrees << "° about y, horizontal";
        EXPECT_NEAR(y.y / reference.y, 1.0, 0.03) << degrees << "° about y, vertical";
        EXPECT_NEAR(x.y / reference.y, std::cos(phi), 0.03) << degrees << "° about x, vertical";
        EXPECT_NEAR(x.x / reference.x, 1.0, 0.03) << degrees << "° about x, horizontal";
        std::printf("  tilt %.0f° (cos %.3f): about y, spread x/facing %.4f, y/facing %.4f; about x, y/facing %.4f, "
                    "x/facing %.4f\n",
                    degrees, std::cos(phi), y.x / reference.x, y.y / reference.y, x.y / reference.y, x.x / reference.x);
    }
}

TEST(PscbfStage, TheCentreOfAnImpulseKeepsTheSpike) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    const SyntheticFrame frame = impulseOnPlane({0.0, 0.0, 1.0});
    const sss::SssParams params = pscbfParams();
    const auto out = runStage(frame, params);
    const sss::Kernel kernel = sss::makeKernel(params);
    const double pixelsPerMm = frame.focalLengthPixels / (frame.mmPerUnit * kFacingDepth);
    const auto& spike = sss::mikkelsenSkinProfile().spike;
    for (int c = 0; c < 3; ++c) {
        // The broad part's value at the impulse: per axis, the share of each tap that the linear interpolation puts
        // on the centre texel, Σ w_i max(0, 1 − |o_i| · px/mm); the 2-D value is its square.
        double axis = 0.0;
        for (const auto& tap : kernel.stages[0].taps)
            axis += tap.weight[c] * std::max(0.0, 1.0 - std::abs(tap.offsetMm) * pixelsPerMm);
        const double expected = spike[c] + (1.0 - spike[c]) * axis * axis;
        const double centre = out[frame.index(kCentre[0], kCentre[1])][c];
        EXPECT_GE(centre, spike[c]) << "channel " << c;
        EXPECT_NEAR(centre, expected, 1e-5) << "channel " << c;
        std::printf("  channel %d: centre keeps %.5f (spike %.2f + broad %.5f)\n", c, centre, spike[c],
                    centre - spike[c]);
    }
}

TEST(PscbfStage, NonSkinTapsAreDiscardedAndRenormalised) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    // Left half skin at colour 1, right half non-skin at colour 100: a skin pixel next to the border keeps exactly 1
    // (the non-skin taps carry no weight; the rest is renormalised), and the non-skin half is copied.
    SyntheticFrame frame = plane({0.0, 0.0, 1.0}, kFacingDepth, kCentre);
    for (int y = 0; y < frame.height; ++y)
        for (int x = 0; x < frame.width; ++x)
            frame.diffuse[frame.index(x, y)] = x < kCentre[0] ? std::array<float, 4>{1.0f, 1.0f, 1.0f, 1.0f}
                                                              : std::array<float, 4>{100.0f, 100.0f, 100.0f, 0.0f};
    const auto out = runStage(frame, pscbfParams());
    float worst = 0.0f;
    for (int y = 0; y < frame.height; ++y)
        for (int x = 0; x < frame.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const float expected = x < kCentre[0] ? 1.0f : 100.0f;
                worst = std::max(worst, std::abs(out[frame.index(x, y)][c] - expected));
            }
    EXPECT_LT(worst, 1e-5f);
}

TEST(PscbfStage, ExtensionsReachThePasses) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    // Two skin halves at the same depth, light 1 on the left, 0 on the right; what reaches the right half crossed the
    // border. E2 (albedos ΔE*ab ≈ 60 apart) and E1 (F = 1 vs 2) must cut it; E3 "reduce" on a plane (κ = 0) shrinks
    // the footprint to nothing, so nothing moves at all.
    SyntheticFrame frame = plane({0.0, 0.0, 1.0}, kFacingDepth, kCentre);
    for (int y = 0; y < frame.height; ++y)
        for (int x = 0; x < frame.width; ++x) {
            const bool left = x < kCentre[0];
            frame.diffuse[frame.index(x, y)] =
                left ? std::array<float, 4>{1.0f, 1.0f, 1.0f, 1.0f} : std::array<float, 4>{0.0f, 0.0f, 0.0f, 1.0f};
            frame.albedo[frame.index(x, y)] =
                left ? std::array<float, 4>{0.8f, 0.5f, 0.4f, 1.0f} : std::array<float, 4>{0.1f, 0.5f, 0.2f, 1.0f};
            frame.aux[frame.index(x, y)] = left ? 1.0f : 2.0f;
        }
    auto crossed = [&](const sss::SssParams& params) {
        const auto out = runStage(frame, params);
        double sum = 0.0;
        for (int y = 0; y < frame.height; ++y)
            for (int x = kCentre[0]; x < frame.width; ++x) sum += out[frame.index(x, y)][0];
        return sum;
    };
    const double off = crossed(pscbfParams());
    sss::SssParams lab = pscbfParams();
    lab.labWeight = 0.09; // the thesis's β for the separable methods
    sss::SssParams cbf = pscbfParams();
    cbf.cbf = true;
    sss::SssParams reduce = pscbfParams();
    reduce.curvature = "reduce";
    const double withLab = crossed(lab), withCbf = crossed(cbf), withReduce = crossed(reduce);
    EXPECT_GT(off, 1.0);
    EXPECT_LT(withLab, 0.5 * off);
    EXPECT_LT(withCbf, 0.5 * off);
    EXPECT_LT(withReduce, 1e-6);
    std::printf(
        "  red light crossing the border: off %.4g, lab_weight 0.09 %.4g, cbf %.4g, curvature reduce (flat) %.4g\n",
        off, withLab, withCbf, withReduce);
}

} // namespace skinlab::renderer
