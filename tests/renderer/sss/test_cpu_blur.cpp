// The CPU reference of the screen-space passes: energy, isotropy on 16:9, follow-surface, skin-only writing.
#include "renderer/sss/cpu_blur.h"
#include "renderer/sss/sss_params.h"

#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>
#include <numeric>

using namespace skinlab::renderer::sss;

namespace {
// A fronto-parallel skin plane filling the image at depth `depth` world units; 1 world unit = 1 mm, so
// pixels per mm = f_px / depth.
SurfaceBuffers flatPlane(int width, int height, float pixelsPerMm) {
    SurfaceBuffers s;
    s.width = width;
    s.height = height;
    s.mmPerUnit = 1.0f;
    s.focalLengthPixels = 500.0f;
    s.depth.assign(size_t(width) * height, s.focalLengthPixels / pixelsPerMm);
    s.mask.assign(size_t(width) * height, 1.0f);
    return s;
}

SssParams method(SssMethod m, int samples = 21) {
    SssParams p;
    p.method = m;
    p.samples = samples;
    return p;
}

// The methods of the shared blur passes (the CPU blur mirrors them), from the method table.
const std::vector<SssMethod> kMethods = [] {
    std::vector<SssMethod> out;
    for (const MethodInfo& info : methodTable())
        if (info.blurPasses()) out.push_back(info.method);
    return out;
}();

double channelSum(const std::vector<Rgb>& image, int c) {
    double sum = 0.0;
    for (const auto& p : image) sum += p[c];
    return sum;
}
} // namespace

TEST(CpuBlur, UniformSkinPlaneIsUnchanged) {
    const SurfaceBuffers plane = flatPlane(48, 32, 3.0f);
    const std::vector<Rgb> flat(plane.mask.size(), Rgb{0.8f, 0.5f, 0.3f});
    for (SssMethod m : kMethods) {
        const auto out = applyKernel(plane, flat, makeKernel(method(m)), BlurSettings{});
        for (const auto& p : out) {
            // Float sums of ≤ 6 × 21 normalised weights: within 1e-5 relative.
            EXPECT_NEAR(p[0], 0.8f, 1e-5f) << methodName(m);
            EXPECT_NEAR(p[2], 0.3f, 1e-5f) << methodName(m);
        }
    }
}

TEST(CpuBlur, ImpulseEnergyIsConservedOnAFlatPlane) {
    // A constant footprint makes the gather filter equal its scatter transpose: total light is conserved exactly
    // (up to float rounding) when the kernel stays inside the image.
    const SurfaceBuffers plane = flatPlane(128, 128, 3.0f);
    std::vector<Rgb> impulse(plane.mask.size(), Rgb{0, 0, 0});
    impulse[64 * 128 + 64] = Rgb{1000.0f, 1000.0f, 1000.0f};
    impulse[60 * 128 + 70] = Rgb{500.0f, 200.0f, 100.0f};
    for (SssMethod m : kMethods) {
        const auto out = applyKernel(plane, impulse, makeKernel(method(m)), BlurSettings{});
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(channelSum(out, c) / channelSum(impulse, c), 1.0, 1e-4) << methodName(m) << " ch " << c;
        // And it did spread: the impulse pixel lost light.
        EXPECT_LT(out[64 * 128 + 64][0], 900.0f) << methodName(m);
    }
}

TEST(CpuBlur, ImpulseSpreadsEquallyOnBothAxesOfA16By9Image) {
    const int width = 320, height = 180;
    const SurfaceBuffers plane = flatPlane(width, height, 8.0f);
    std::vector<Rgb> impulse(plane.mask.size(), Rgb{0, 0, 0});
    const int cx = width / 2, cy = height / 2;
    impulse[size_t(cy) * width + cx] = Rgb{1.0f, 1.0f, 1.0f};
    for (SssMethod m : kMethods) {
        const auto out = applyKernel(plane, impulse, makeKernel(method(m)), BlurSettings{});
        for (int c = 0; c < 3; ++c) {
            double sum = 0, xx = 0, yy = 0;
            for (int y = 0; y < height; ++y)
                for (int x = 0; x < width; ++x) {
                    const double v = out[size_t(y) * width + x][c];
                    sum += v;
                    xx += v * (x - cx) * (x - cx);
                    yy += v * (y - cy) * (y - cy);
                }
            const double ratio = std::sqrt(xx / sum) / std::sqrt(yy / sum);
            EXPECT_NEAR(ratio, 1.0, 0.02) << methodName(m) << " channel " << c;
            // It did spread (blue, the narrowest channel, has an RMS width of ≈ 0.16 mm = 1.3 px here).
            EXPECT_GT(std::sqrt(xx / sum), 0.5) << methodName(m) << " channel " << c << ": no spread";
        }
    }
}

TEST(CpuBlur, FollowSurfaceStopsLightCrossingADepthStep) {
    // Left half at depth D, right half 20 mm behind; a bright column on the left, next to the step.
    const int width = 96, height = 32;
    SurfaceBuffers surface = flatPlane(width, height, 3.0f);
    for (int y = 0; y < height; ++y)
        for (int x = width / 2; x < width; ++x) surface.depth[size_t(y) * width + x] += 20.0f;
    std::vector<Rgb> light(surface.mask.size(), Rgb{0, 0, 0});
    for (int y = 0; y < height; ++y) light[size_t(y) * width + width / 2 - 2] = Rgb{1, 1, 1};
    auto crossed = [&](const std::vector<Rgb>& image) {
        double sum = 0;
        for (int y = 0; y < height; ++y)
            for (int x = width / 2; x < width; ++x) sum += image[size_t(y) * width + x][0];
        return sum;
    };
    for (SssMethod m : kMethods) {
        const Kernel kernel = makeKernel(method(m));
        const double off = crossed(applyKernel(surface, light, kernel, BlurSettings{false, 0.5f}));
        const double on = crossed(applyKernel(surface, light, kernel, BlurSettings{true, 0.5f}));
        EXPECT_GT(off, 0.05) << methodName(m);
        // 20 mm step × 0.5/mm saturates s = 1: nothing crosses.
        EXPECT_LT(on, 1e-6 * off) << methodName(m);
    }
}

TEST(CpuBlur, OnlySkinIsWrittenAndNoLightComesFromNonSkin) {
    // Left half skin (black), right half non-skin (bright): skin must stay black, non-skin unchanged.
    const int width = 64, height = 16;
    SurfaceBuffers surface = flatPlane(width, height, 3.0f);
    std::vector<Rgb> image(surface.mask.size(), Rgb{0, 0, 0});
    for (int y = 0; y < height; ++y)
        for (int x = width / 2; x < width; ++x) {
            surface.mask[size_t(y) * width + x] = 0.0f;
            image[size_t(y) * width + x] = Rgb{5.0f, 4.0f, 3.0f};
        }
    // A lit skin pixel next to the edge: its light must not be written onto non-skin pixels.
    image[8 * width + width / 2 - 1] = Rgb{1, 1, 1};
    for (SssMethod m : kMethods) {
        const auto out = applyKernel(surface, image, makeKernel(method(m)), BlurSettings{false, 0.5f});
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const size_t i = size_t(y) * width + x;
                if (x >= width / 2) {
                    // Non-skin: bit-identical copy (Σ accumulate = 1 exactly in float for 1-stage methods; the
                    // six-stage sum of d'Eon weights rounds within 1e-6).
                    EXPECT_NEAR(out[i][0], 5.0f, 5e-6f) << methodName(m);
                } else {
                    EXPECT_LE(out[i][0], 1.0f) << methodName(m) << " at " << x << "," << y;
                }
            }
        // The skin side keeps its own light: Σ over skin ≈ 1 (none lost to or taken from non-skin). Not exact: a tap
        // straddling a skin and a non-skin texel takes the receiving pixel's colour for the non-skin part, so next to
        // the edge the gather is not exactly the transpose of a scatter (measured loss 2.4e-4 for 12 passes).
        double skin = 0;
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width / 2; ++x) skin += out[size_t(y) * width + x][1];
        EXPECT_NEAR(skin, 1.0, 1e-3) << methodName(m);
    }
}

// The extensions on the CPU (docs/extensions.md): E2 keeps a differently coloured region's light out of the skin,
// E1 stops light at a step of the auxiliary image like follow-surface at a depth step; both keep a uniform
// region's value (the renormalisation).
TEST(CpuBlur, LabWeightKeepsPaintLightOutOfTheSkin) {
    const int width = 64, height = 16;
    SurfaceBuffers surface = flatPlane(width, height, 3.0f);
    surface.albedo.resize(size_t(width) * height);
    std::vector<Rgb> image(surface.albedo.size());
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            // Skin on the left, a dark blue "paint" inside the skin mask on the right, lit alike.
            surface.albedo[size_t(y) * width + x] = x < width / 2 ? Rgb{0.6f, 0.42f, 0.34f} : Rgb{0.05f, 0.08f, 0.4f};
            image[size_t(y) * width + x] = surface.albedo[size_t(y) * width + x];
        }
    for (SssMethod m : kMethods) {
        SssParams p = method(m);
        p.followSurface = false;
        auto worstSkinChange = [&](double beta) {
            p.labWeight = beta;
            const auto out = applyKernel(surface, image, makeKernel(p), blurSettingsFromParams(p));
            float worst = 0.0f;
            for (int x = 0; x < width / 2; ++x)
                worst = std::max(worst, std::abs(out[8 * width + x][0] - image[8 * width + x][0]));
            return worst;
        };
        const float off = worstSkinChange(0.0);
        const float on = worstSkinChange(0.5);
        EXPECT_GT(off, 0.05f) << methodName(m);
        // ΔE*ab ≈ 60 between the two albedos: exp(−0.5 · 60) ≈ 1e-13, so the skin keeps its value to rounding.
        EXPECT_LT(on, 1e-5f) << methodName(m);
    }
}

TEST(CpuBlur, CbfStopsLightAtAStepOfTheAuxiliaryImage) {
    const int width = 64, height = 16;
    SurfaceBuffers surface = flatPlane(width, height, 3.0f);
    surface.aux.resize(size_t(width) * height);
    std::vector<Rgb> image(surface.aux.size());
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            surface.aux[size_t(y) * width + x] = x < width / 2 ? 1.0f : 3.0f; // F differs by 2 across x = 32
            image[size_t(y) * width + x] = x < width / 2 ? Rgb{0.2f, 0.2f, 0.2f} : Rgb{1.0f, 1.0f, 1.0f};
        }
    for (SssMethod m : kMethods) {
        SssParams p = method(m);
        p.followSurface = false;
        auto crossed = [&](bool cbf) {
            p.cbf = cbf;
            const auto out = applyKernel(surface, image, makeKernel(p), blurSettingsFromParams(p));
            double light = 0.0; // light that reached the dark side
            for (int x = 0; x < width / 2; ++x) light += out[8 * width + x][1] - 0.2;
            return light;
        };
        const double off = crossed(false);
        const double on = crossed(true);
        EXPECT_GT(off, 0.05) << methodName(m);
        // λ = 10: exp(−10 · 2) ≈ 2e-9 per crossing tap; what remains is float rounding of 32 sums of 0.2
        // (measured ≤ 2e-6), against 0.09–0.2 without cbf.
        EXPECT_LT(std::abs(on), 1e-5) << methodName(m);
    }
}
