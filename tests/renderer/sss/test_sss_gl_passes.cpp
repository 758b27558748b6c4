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

#define SKINLAB_REQUIRE_GL()                                                                                           \
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
    // Extension inputs (the albedo, aux.Y and curvature.Y AOVs of a render): zeros where the test gives none.
    gl::Texture albedoTexture = gl::createTexture2D(GL_RGBA32F, w, h);
    gl::Texture auxTexture = gl::createTexture2D(GL_R32F, w, h);
    gl::Texture curvatureTexture = gl::createTexture2D(GL_R32F, w, h);
    std::vector<float> albedo(rgba.size(), 0.0f);
    for (size_t i = 0; i < surface.albedo.size(); ++i)
        for (int c = 0; c < 3; ++c) albedo[4 * i + c] = surface.albedo[i][c];
    const std::vector<float> zeros(size_t(w) * h, 0.0f);
    glTextureSubImage2D(albedoTexture.get(), 0, 0, 0, w, h, GL_RGBA, GL_FLOAT, albedo.data());
    glTextureSubImage2D(auxTexture.get(), 0, 0, 0, w, h, GL_RED, GL_FLOAT,
                        surface.aux.empty() ? zeros.data() : surface.aux.data());
    glTextureSubImage2D(curvatureTexture.get(), 0, 0, 0, w, h, GL_RED, GL_FLOAT,
                        surface.curvature.empty() ? zeros.data() : surface.curvature.data());
    gl::SssStageInputs inputs;
    inputs.diffuse = diffuseTexture.get();
    inputs.linearDepth = depthTexture.get();
    inputs.skinMask = maskTexture.get();
    inputs.albedo = albedoTexture.get();
    inputs.aux = auxTexture.get();
    inputs.curvature = curvatureTexture.get();
    inputs.width = w;
    inputs.height = h;
    inputs.focalLengthPixels = surface.focalLengthPixels;
    inputs.mmPerUnit = surface.mmPerUnit;
    gl::SssStageSettings settings;
    settings.sss = params;
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

// The methods of the shared blur passes, from the method table (renderer/sss/sss_params.h).
const std::vector<sss::SssMethod> kMethods = [] {
    std::vector<sss::SssMethod> out;
    for (const sss::MethodInfo& info : sss::methodTable())
        if (info.blurPasses()) out.push_back(info.method);
    return out;
}();

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
    const std::vector<Variant> variants{{params(sss::methodId("gaussian-sum")), "gaussian-sum"},
                                        {params(sss::methodId("separable")), "separable"},
                                        {params(sss::methodId("separable"), 11, false, sss::TapPlacement::Importance),
                                         "separable/importance/no-follow"},
                                        {params(sss::methodId("artistic"), 25), "artistic"},
                                        {params(sss::methodId("artistic"), 7, false), "artistic/7/no-follow"}};
    for (const auto& v : variants) {
        const sss::Kernel kernel = sss::makeKernel(v.p);
        const auto cpu = sss::applyKernel(surface, diffuse, kernel,
                                          sss::BlurSettings{v.p.followSurface, static_cast<float>(v.p.followSurfaceK)});
        const auto gpu = runOnGpu(surface, diffuse, v.p);
        float maxDiff = 0.0f;
        for (size_t i = 0; i < cpu.size(); ++i)
            for (int c = 0; c < 3; ++c) maxDiff = std::max(maxDiff, std::abs(cpu[i][c] - gpu[i][c]));
        // 1e-3: both sides compute in float32 in the same order; differences come from fused
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
            diffuse[size_t(y) * w + x] = Rgb{0.8f + 0.2f * std::sin(0.9f * x + 0.3f * y),
                                             0.5f + 0.1f * std::cos(1.3f * y), 0.3f + 0.1f * std::sin(0.5f * x * 0.7f)};
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
            EXPECT_NEAR(sum, 1.0, 1e-4) << sss::methodName(m) << " channel " << c; // energy of the impulse
            EXPECT_GT(std::sqrt(xx / sum), 0.5) << sss::methodName(m) << ": no spread";
        }
    }
}

namespace {

// The test image of MatchTheCpuReferenceOnATestImage plus the extension inputs: an albedo with a "paint" rectangle
// of a very different colour inside the skin mask (what sss.lab_weight must separate), an auxiliary image F with a
// step between the two depth planes and smooth variation (sss.cbf), and a curvature that varies from 0 (flat) to
// beyond 1/20 mm (fully curved) across the image (sss.curvature).
struct ExtensionTestImage {
    sss::SurfaceBuffers surface;
    std::vector<Rgb> diffuse;
};

ExtensionTestImage extensionTestImage() {
    const int w = 96, h = 54;
    ExtensionTestImage image;
    image.surface = flatPlane(w, h, 2.5f);
    sss::SurfaceBuffers& surface = image.surface;
    surface.albedo.resize(size_t(w) * h);
    surface.aux.resize(size_t(w) * h);
    surface.curvature.resize(size_t(w) * h);
    image.diffuse.resize(size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            const bool paint = x >= 20 && x < 34 && y >= 12 && y < 30;
            surface.albedo[i] = paint
                                    ? Rgb{0.05f, 0.08f, 0.4f}
                                    : Rgb{0.55f + 0.1f * std::sin(0.2f * x), 0.35f, 0.25f + 0.05f * std::cos(0.3f * y)};
            if (x >= 40) surface.depth[i] += 30.0f;
            surface.aux[i] = (x >= 40 ? 1.6f : 1.0f) + 0.05f * std::sin(0.13f * x + 0.21f * y);
            // κ in 1/world unit (mm_per_unit = 1): 0 … 0.075/mm, normalised c = 0 … 1 (clamped from 0.05/mm on).
            surface.curvature[i] = 0.075f * float(x) / float(w - 1);
            if (x >= 60 && x < 70 && y >= 20 && y < 34) surface.mask[i] = 0.0f;
            if (y >= 45 && y < 48) surface.mask[i] = 0.5f;
            if (x >= 86) {
                surface.mask[i] = 0.0f;
                surface.depth[i] = std::numeric_limits<float>::infinity();
            }
            const Rgb light{1.2f + 0.4f * std::sin(0.31f * x) * std::cos(0.17f * y), 1.0f, 0.9f};
            for (int c = 0; c < 3; ++c) image.diffuse[i][c] = light[c] * surface.albedo[i][c];
            if ((x * 7 + y * 13) % 97 == 0) image.diffuse[i] = Rgb{4.0f, 3.0f, 2.0f};
        }
    return image;
}

float maxAbsDifference(const std::vector<Rgb>& a, const std::vector<Rgb>& b) {
    float result = 0.0f;
    for (size_t i = 0; i < a.size(); ++i)
        for (int c = 0; c < 3; ++c) result = std::max(result, std::abs(a[i][c] - b[i][c]));
    return result;
}

} // namespace

TEST(SssGlPasses, ExtensionsMatchTheCpuReference) {
    SKINLAB_REQUIRE_GL();
    const ExtensionTestImage image = extensionTestImage();
    struct Extensions {
        const char* name;
        bool cbf;
        double lambda;
        double beta;
        const char* curvature;
        const char* input = "albedo";
        double referenceMm = 20.0;
    };
    const std::vector<Extensions> extensions{
        {"cbf", true, 10.0, 0.0, "off"},
        {"cbf lambda 1000", true, 1000.0, 0.0, "off"}, // rejects nearly every tap off the centre texel
        {"lab_weight 0.09", false, 10.0, 0.09, "off"},
        {"lab_weight 0.5", false, 10.0, 0.5, "off"},
        {"curvature increase", false, 10.0, 0.0, "increase"},
        {"curvature reduce", false, 10.0, 0.0, "reduce"},
        {"curvature reduce-floor", false, 10.0, 0.0, "reduce-floor"},
        {"cbf + lab + reduce-floor", true, 10.0, 0.09, "reduce-floor"},
        // sss.extension_input = "lit": the colour each pass blurs replaces the albedo (Lab, and F's grey).
        {"cbf lit", true, 10.0, 0.0, "off", "lit"},
        {"lab_weight 0.09 lit", false, 10.0, 0.09, "off", "lit"},
        {"lab_weight 0.5 lit", false, 10.0, 0.5, "off", "lit"},
        // sss.curvature_reference_mm: c = saturate(κ · 60 mm), every pixel past κ = 1/60 mm counts as fully curved.
        {"reduce-floor reference 60 mm", false, 10.0, 0.0, "reduce-floor", "albedo", 60.0}};
    for (sss::SssMethod method : kMethods) {
        const sss::SssParams off = params(method);
        const auto gpuOff = runOnGpu(image.surface, image.diffuse, off);
        for (const auto& e : extensions) {
            sss::SssParams p = off;
            p.cbf = e.cbf;
            p.cbfLambda = e.lambda;
            p.labWeight = e.beta;
            p.curvature = e.curvature;
            p.extensionInput = e.input;
            p.curvatureReferenceMm = e.referenceMm;
            const auto cpu =
                sss::applyKernel(image.surface, image.diffuse, sss::makeKernel(p), sss::blurSettingsFromParams(p));
            const auto gpu = runOnGpu(image.surface, image.diffuse, p);
            const float difference = maxAbsDifference(cpu, gpu);
            // 1e-3 as in MatchTheCpuReferenceOnATestImage: float32 on both sides in the same order; the extension
            // weights add exp/pow of the driver (a few ulps each).
            EXPECT_LE(difference, 1e-3f) << sss::methodName(method) << " " << e.name;
            // Not a test that cannot fail: every extension changes the output by far more than the tolerance.
            const float changed = maxAbsDifference(gpu, gpuOff);
            EXPECT_GT(changed, 0.01f) << sss::methodName(method) << " " << e.name << ": the extension changed nothing";
            for (const auto& pixel : gpu)
                for (float v : pixel) ASSERT_TRUE(std::isfinite(v)) << sss::methodName(method) << " " << e.name;
            std::printf("  %-13s %-28s max |GL - CPU| = %.3g (changed the image by up to %.3g)\n",
                        std::string(sss::methodName(method)).c_str(), e.name, double(difference), double(changed));
        }
    }
}

// The two inputs differ where the lit colour does and the albedo does not: a skin plane of one albedo with a shadow
// terminator (the light drops to 5 % at x = 48). With the albedo input the CIELAB weight is 1 everywhere (one albedo),
// so the blur is the unweighted one; with the lit input it cuts the blur at the terminator (thesis Eq. 3.13's "lab
// color of the image I"), leaving the shadowed side darker next to the edge.
TEST(SssGlPasses, LitExtensionInputCutsAtAShadowTerminator) {
    SKINLAB_REQUIRE_GL();
    const int w = 96, h = 32;
    sss::SurfaceBuffers surface = flatPlane(w, h, 2.5f);
    surface.albedo.assign(size_t(w) * h, Rgb{0.6f, 0.4f, 0.3f});
    surface.aux.assign(size_t(w) * h, 1.0f);
    std::vector<Rgb> diffuse(size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float light = x < 48 ? 1.0f : 0.05f;
            for (int c = 0; c < 3; ++c) diffuse[size_t(y) * w + x][c] = light * surface.albedo[0][c];
        }
    sss::SssParams off = params(sss::methodId("separable"));
    off.followSurface = false;
    sss::SssParams albedo = off, lit = off;
    albedo.labWeight = lit.labWeight = 0.09;
    lit.extensionInput = "lit";
    const auto gpuOff = runOnGpu(surface, diffuse, off);
    const auto gpuAlbedo = runOnGpu(surface, diffuse, albedo);
    const auto gpuLit = runOnGpu(surface, diffuse, lit);
    EXPECT_LE(maxAbsDifference(gpuAlbedo, gpuOff), 1e-5f) << "one albedo: the albedo input must not weigh any tap";
    const size_t shadowed = size_t(h / 2) * w + 50; // 2 pixels into the shadow
    EXPECT_GT(gpuOff[shadowed][0], 0.05f * 0.6f + 0.02f) << "the unweighted blur carries light across the terminator";
    EXPECT_LT(gpuLit[shadowed][0], 0.5f * (gpuOff[shadowed][0] + 0.05f * 0.6f))
        << "the lit input should keep most of the light on its side";
    const auto cpuLit = sss::applyKernel(surface, diffuse, sss::makeKernel(lit), sss::blurSettingsFromParams(lit));
    EXPECT_LE(maxAbsDifference(cpuLit, gpuLit), 1e-3f);
}

namespace {
// RMS distance (pixels) of the light of channel `c` from (cx, cy), and its total.
struct Spread {
    double rms = 0.0;
    double energy = 0.0;
};
Spread spreadOf(const std::vector<Rgb>& image, int w, int h, int cx, int cy, int c) {
    double sum = 0.0, moment = 0.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double v = image[size_t(y) * w + x][c];
            sum += v;
            moment += v * ((x - cx) * (x - cx) + (y - cy) * (y - cy));
        }
    return {std::sqrt(moment / sum), sum};
}
} // namespace

TEST(SssGlPasses, CurvatureReduceLeavesFlatSkinUnblurred) {
    SKINLAB_REQUIRE_GL();
    // A flat plane: curvature 0 everywhere, so `reduce` scales the footprint by c = 0 (thesis: flat areas lose SSS)
    // and every method leaves the image as it was; with `off` the same image is visibly blurred.
    const int w = 64, h = 48;
    sss::SurfaceBuffers plane = flatPlane(w, h, 3.0f);
    plane.curvature.assign(size_t(w) * h, 0.0f);
    std::vector<Rgb> image(size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            image[size_t(y) * w + x] = Rgb{((x / 4 + y / 4) % 2) ? 1.0f : 0.2f, 0.5f, 0.3f + 0.01f * float(x)};
    for (sss::SssMethod method : kMethods) {
        sss::SssParams p = params(method);
        const float blurred = maxAbsDifference(runOnGpu(plane, image, p), image);
        p.curvature = "reduce";
        // All taps land on the centre texel with weights summing to 1: the centre back up to float rounding.
        const float unblurred = maxAbsDifference(runOnGpu(plane, image, p), image);
        EXPECT_GT(blurred, 0.1f) << sss::methodName(method);
        EXPECT_LE(unblurred, 1e-5f) << sss::methodName(method);
        std::printf("  %-13s flat plane: max change %.3g with curvature off, %.3g with reduce\n",
                    std::string(sss::methodName(method)).c_str(), double(blurred), double(unblurred));
    }
}

TEST(SssGlPasses, CurvatureScalesTheSpreadOfAnImpulse) {
    SKINLAB_REQUIRE_GL();
    // An impulse on a plane of uniform curvature: its RMS spread scales with the footprint multiplier of each
    // strategy (docs/extensions.md, E3): reduce-floor on flat skin keeps floor × the width, reduce keeps c × the
    // width, increase on fully curved skin doubles it; the energy stays 1 in every case.
    const int w = 256, h = 256;
    const int cx = w / 2, cy = h / 2;
    sss::SurfaceBuffers plane = flatPlane(w, h, 8.0f);
    std::vector<Rgb> impulse(size_t(w) * h, Rgb{0, 0, 0});
    impulse[size_t(cy) * w + cx] = Rgb{1, 1, 1};
    const float fullyCurved = 1.0f / sss::kCurvatureReferenceRadiusMm; // κ (1/mm = 1/unit here) with c = 1
    struct Case {
        const char* strategy;
        float curvature; // κ, 1/world unit
        double floor;
        double expectedScale;
    };
    const std::vector<Case> cases{{"reduce-floor", 0.0f, 0.5, 0.5},        {"reduce-floor", 0.0f, 0.3, 0.3},
                                  {"reduce-floor", fullyCurved, 0.5, 1.0}, {"reduce", 0.6f * fullyCurved, 0.5, 0.6},
                                  {"increase", fullyCurved, 0.5, 2.0},     {"increase", 0.0f, 0.5, 1.0}};
    for (sss::SssMethod method :
         {sss::methodId("separable"), sss::methodId("artistic"), sss::methodId("gaussian-sum")}) {
        const Spread off = spreadOf(runOnGpu(plane, impulse, params(method)), w, h, cx, cy, 0);
        for (const auto& k : cases) {
            sss::SssParams p = params(method);
            p.curvature = k.strategy;
            p.curvatureFloor = k.floor;
            plane.curvature.assign(size_t(w) * h, k.curvature);
            const Spread spread = spreadOf(runOnGpu(plane, impulse, p), w, h, cx, cy, 0);
            const double scale = spread.rms / off.rms;
            // 6 %: the linear interpolation between texels adds up to ¼ px² of variance per pass, which does not
            // scale with the footprint (red RMS width 5.7–13 px here with the strategy off; 1.7 px at 0.3 × the
            // artistic kernel, where ≤ ½ px² of interpolation variance is a 5 % excess).
            EXPECT_NEAR(scale, k.expectedScale, 0.06 * k.expectedScale)
                << sss::methodName(method) << " " << k.strategy << " c=" << k.curvature / fullyCurved;
            // 1e-3: gaussian-sum's widest lobe doubled (increase) reaches the image border (128 px away) and loses
            // 3e-4 of its energy there; every other case keeps it within 1e-5.
            EXPECT_NEAR(spread.energy, 1.0, 1e-3) << sss::methodName(method) << " " << k.strategy;
            std::printf("  %-13s %-12s c = %.2f floor %.1f: red RMS spread %.2f px = %.3f x off (expected %.2f)\n",
                        std::string(sss::methodName(method)).c_str(), k.strategy, double(k.curvature / fullyCurved),
                        k.floor, spread.rms, scale, k.expectedScale);
        }
    }
}
