// The GL passes of the SSS methods (renderer/gl/sss_blur_pass, sss_kernel_method behind sss_stage) against the CPU
// reference renderer/sss/cpu_blur, plus energy and isotropy on the GPU (label gl; llvmpipe in CI). Inputs are
// synthetic textures uploaded directly, so every pixel's expected value is known from the CPU mirror.
#include "renderer/gl/egl_context.h"
#include "renderer/gl/gl_resources.h"
#include "renderer/gl/shader_library.h"
#include "renderer/gl/sss_stage.h"
#include "renderer/sss/cpu_blur.h"
#include "renderer/sss/kernel.h"

#include <cmath>
#include <cstdio>
#include <gtest/gtest.h>
#include <limits>
#include <memory>

using namespace skinlab::renderer;
using sss::Rgb;

namespace {

struct GlFixture {
    std::unique_ptr<gl::EglContext> context;
    std::unique_ptr<gl::ShaderLibrary> shaders;
    std::unique_ptr<gl::SssStage> stage;
    std::string failure;
};

GlFixture& fixture() {
    static GlFixture f;
    static bool tried = false;
    if (!tried) {
        tried = true;
        try {
            f.context = std::make_unique<gl::EglContext>();
            f.shaders = std::make_unique<gl::ShaderLibrary>();
            f.stage = std::make_unique<gl::SssStage>(*f.shaders);
        } catch (const std::exception& e) {
            f.failure = e.what();
            f.context.reset();
        }
    }
    return f;
}

#define SKINLAB_REQUIRE_GL()                                                                                        \
    if (!fixture().context) GTEST_SKIP() << "no EGL/OpenGL 4.5 context: " << fixture().failure

// Runs the GL SSS stage on CPU-side buffers and returns the output colour (rgb).
std::vector<Rgb> runOnGpu(const sss::SurfaceBuffers& surface, const std::vector<Rgb>& diffuse,
                          const sss::SssParams& params) {
    const int w = surface.width, h = surface.height;
    std::vector<float> rgba(size_t(w) * h * 4);
    for (size_t i = 0; i < diffuse.size(); ++i) {
        for (int c = 0; c < 3; ++c) rgba[4 * i + c] = diffuse[i][c];
        rgba[4 * i + 3] = surface.mask[i];
    }
    gl::Texture diffuseTexture = gl::createTexture2D(GL_RGBA32F, w, h);
    gl::Texture depthTexture = gl::createTexture2D(GL_R32F, w, h);
    gl::Texture maskTexture = gl::createTexture2D(GL_R32F, w, h);
    gl::Texture output = gl::createTexture2D(GL_RGBA32F, w, h);
    glTextureSubImage2D(diffuseTexture.get(), 0, 0, 0, w, h, GL_RGBA, GL_FLOAT, rgba.data());
    glTextureSubImage2D(depthTexture.get(), 0, 0, 0, w, h, GL_RED, GL_FLOAT, surface.depth.data());
    glTextureSubImage2D(maskTexture.get(), 0, 0, 0, w, h, GL_RED, GL_FLOAT, surface.mask.data());
    gl::SssStageInputs inputs;
    inputs.diffuse = diffuseTexture.get();
    inputs.linearDepth = depthTexture.get();
    inputs.skinMask = maskTexture.get();
    inputs.width = w;
    inputs.height = h;
    inputs.focalLengthPixels = surface.focalLengthPixels;
    inputs.mmPerUnit = surface.mmPerUnit;
    gl::SssStageSettings settings;
    settings.method = std::string(sss::methodName(params.method));
    settings.sss = params.toJson();
    fixture().stage->run(inputs, settings, output.get());
    std::vector<float> out(rgba.size());
    glGetTextureImage(output.get(), 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(out.size() * sizeof(float)), out.data());
    gl::checkGl("test readback");
    std::vector<Rgb> result(diffuse.size());
    for (size_t i = 0; i < result.size(); ++i) result[i] = Rgb{out[4 * i], out[4 * i + 1], out[4 * i + 2]};
    return result;
}

sss::SssParams params(sss::SssMethod method, int samples = 21, bool follow = true,
                      sss::TapPlacement placement = sss::TapPlacement::Quadratic) {
    sss::SssParams p;
    p.method = method;
    p.samples = samples;
    p.followSurface = follow;
    p.placement = placement;
    return p;
}

sss::SurfaceBuffers flatPlane(int width, int height, float pixelsPerMm) {
    sss::SurfaceBuffers s;
    s.width = width;
    s.height = height;
    s.mmPerUnit = 1.0f;
    s.focalLengthPixels = 300.0f;
    s.depth.assign(size_t(width) * height, s.focalLengthPixels / pixelsPerMm);
    s.mask.assign(size_t(width) * height, 1.0f);
    return s;
}

const std::vector<sss::SssMethod> kMethods{sss::SssMethod::GaussianSum, sss::SssMethod::Separable,
                                           sss::SssMethod::Artistic};

} // namespace

TEST(SssGlPasses, MatchTheCpuReferenceOnATestImage) {
    SKINLAB_REQUIRE_GL();
    // 16:9 image: two skin planes 30 mm apart in depth, a non-skin rectangle, a band of half-skin mask, background
    // (+inf depth, mask 0) on the right; a smooth pattern with a few sharp bright features.
    const int w = 96, h = 54;
    sss::SurfaceBuffers surface = flatPlane(w, h, 2.5f);
    std::vector<Rgb> diffuse(size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            if (x >= 40) surface.depth[i] += 30.0f;
            if (x >= 60 && x < 70 && y >= 20 && y < 34) surface.mask[i] = 0.0f;
            if (y >= 45 && y < 48) surface.mask[i] = 0.5f;
            if (x >= 86) {
                surface.mask[i] = 0.0f;
                surface.depth[i] = std::numeric_limits<float>::infinity();
            }
            diffuse[i] = Rgb{0.6f + 0.4f * std::sin(0.31f * x) * std::cos(0.17f * y),
                             0.4f + 0.3f * std::cos(0.23f * x + 0.11f * y), 0.3f + 0.2f * std::sin(0.07f * x * y)};
            if ((x * 7 + y * 13) % 97 == 0) diffuse[i] = Rgb{4.0f, 3.0f, 2.0f};
        }
    struct Variant {
        sss::SssParams p;
        const char* name;
    };
    const std::vector<Variant> variants{
        {params(sss::SssMethod::GaussianSum), "gaussian-sum"},
        {params(sss::SssMethod::Separable), "separable"},
        {params(sss::SssMethod::Separable, 11, false, sss::TapPlacement::Importance), "separable/importance/no-follow"},
        {params(sss::SssMethod::Artistic, 25), "artistic"},
        {params(sss::SssMethod::Artistic, 7, false), "artistic/7/no-follow"}};
    for (const auto& v : variants) {
        const sss::Kernel kernel = sss::makeKernel(v.p);
        const auto cpu = sss::applyKernel(surface, diffuse, kernel,
                                          sss::BlurSettings{v.p.followSurface, static_cast<float>(v.p.followSurfaceK)});
        const auto gpu = runOnGpu(surface, diffuse, v.p);
        float maxDiff = 0.0f;
        for (size_t i = 0; i < cpu.size(); ++i)
            for (int c = 0; c < 3; ++c) maxDiff = std::max(maxDiff, std::abs(cpu[i][c] - gpu[i][c]));
        // 1e-3 (issue 3): both sides compute in float32 in the same order; differences come from fused
        // multiply-adds and the driver's mix(), i.e. a few ulps per tap.
        EXPECT_LE(maxDiff, 1e-3f) << v.name;
        std::printf("  %-32s max |GL - CPU| = %.3g\n", v.name, double(maxDiff));
        // The test can fail: the blur changed the image by far more than the tolerance.
        float changed = 0.0f;
        for (size_t i = 0; i < cpu.size(); ++i) changed = std::max(changed, std::abs(cpu[i][0] - diffuse[i][0]));
        EXPECT_GT(changed, 0.1f) << v.name;
    }
}

TEST(SssGlPasses, KeepTheMeanOfALitSkinPlaneAwayFromBorders) {
    SKINLAB_REQUIRE_GL();
    // Lit skin plane with texture-like variation: the mean inside (away from the borders by the kernel's support)
    // stays within 0.5 %.
    const int w = 192, h = 128;
    const sss::SurfaceBuffers plane = flatPlane(w, h, 3.0f);
    std::vector<Rgb> diffuse(size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            diffuse[size_t(y) * w + x] = Rgb{0.8f + 0.2f * std::sin(0.9f * x + 0.3f * y), 0.5f + 0.1f * std::cos(1.3f * y),
                                             0.3f + 0.1f * std::sin(0.5f * x * 0.7f)};
    for (sss::SssMethod m : kMethods) {
        const sss::SssParams p = params(m);
        const int margin = static_cast<int>(std::ceil(sss::makeKernel(p).supportRadiusMm() * 3.0)) + 1;
        ASSERT_LT(2 * margin, h) << "image too small for the kernel";
        const auto out = runOnGpu(plane, diffuse, p);
        for (int c = 0; c < 3; ++c) {
            double in = 0.0, blurred = 0.0;
            for (int y = margin; y < h - margin; ++y)
                for (int x = margin; x < w - margin; ++x) {
                    in += diffuse[size_t(y) * w + x][c];
                    blurred += out[size_t(y) * w + x][c];
                }
            EXPECT_NEAR(blurred / in, 1.0, 0.005) << sss::methodName(m) << " channel " << c;
        }
    }
}

TEST(SssGlPasses, ImpulseSpreadsEquallyOnBothAxesOfA16By9Image) {
    SKINLAB_REQUIRE_GL();
    const int w = 192, h = 108;
    const sss::SurfaceBuffers plane = flatPlane(w, h, 6.0f);
    std::vector<Rgb> impulse(size_t(w) * h, Rgb{0, 0, 0});
    const int cx = w / 2, cy = h / 2;
    impulse[size_t(cy) * w + cx] = Rgb{1, 1, 1};
    for (sss::SssMethod m : kMethods) {
        const auto out = runOnGpu(plane, impulse, params(m));
        for (int c = 0; c < 3; ++c) {
            double sum = 0, xx = 0, yy = 0;
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    const double v = out[size_t(y) * w + x][c];
                    sum += v;
                    xx += v * (x - cx) * (x - cx);
                    yy += v * (y - cy) * (y - cy);
                }
            EXPECT_NEAR(std::sqrt(xx / yy), 1.0, 0.02) << sss::methodName(m) << " channel " << c;
            EXPECT_NEAR(sum, 1.0, 1e-4) << sss::methodName(m) << " channel " << c;  // energy of the impulse
            EXPECT_GT(std::sqrt(xx / sum), 0.5) << sss::methodName(m) << ": no spread";
        }
    }
}
