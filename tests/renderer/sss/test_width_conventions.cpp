// The thesis' sssWidth conventions (renderer/sss/width_conventions.h) against hand-computed values, the demo's
// convention, and a replay of the thesis shaders' steps in pixels.
#include "renderer/sss/width_conventions.h"

#include "renderer/sss/kernel.h"
#include "renderer/sss/sss_params.h"
#include "width_views.h"

#include <cmath>

#include <gtest/gtest.h>

using namespace skinlab::renderer::sss;

using test::kViews;
using test::View;

// By hand: 1.4 × 0.012 × 47.9 = 0.80472 mm; 0.012 × 47.9 / 15 = 0.03832 mm; 1.4 × 1.5 × 1 = 2.1 mm.
TEST(ThesisWidth, HandComputedValues) {
    EXPECT_NEAR(widthMmFromThesisSssWidth(0.012, 47.9, ThesisBlurShader::Separable), 0.80472, 1e-12);
    EXPECT_NEAR(widthMmFromThesisSssWidth(1.5, 1.0, ThesisBlurShader::Separable), 2.1, 1e-12);
    EXPECT_NEAR(widthMmFromThesisSssWidth(0.012, 47.9, ThesisBlurShader::GaussianSum), 0.03832, 1e-12);
    EXPECT_NEAR(widthMmFromThesisSssWidth(1.5, 1.0, ThesisBlurShader::GaussianSum), 0.1, 1e-12);
    EXPECT_DOUBLE_EQ(kThesisSeparableStepFactor, 0.7);
    EXPECT_DOUBLE_EQ(kThesisSeparableEdgePerSssWidth, 1.4);
}

// The demo's conversion overstates the thesis' separable widths by 2 / 1.4 = 1.428571… ≈ 1.43, for every setting.
TEST(ThesisWidth, DemoConventionIsOnePointFourThreeTimesTheThesisSeparable) {
    for (const View v : kViews) {
        const double ratio = widthMmFromDemoSssWidth(v.sssWidth, v.mmPerUnit) /
                             widthMmFromThesisSssWidth(v.sssWidth, v.mmPerUnit, ThesisBlurShader::Separable);
        EXPECT_NEAR(ratio, 10.0 / 7.0, 1e-12) << "sssWidth " << v.sssWidth;
        EXPECT_NEAR(ratio, 1.43, 0.002);
    }
}

// The thesis' separable shaders step sssWidth · (1 / tan(fovY/2)) / z · dir · 0.7 / kernel_range in texture
// coordinates per kernel unit, their kernels spanning ±kernel_range (3 for the demo's kernel, the outermost offset of
// a tabulated one): the edge lies 0.7 · sssWidth · cot(fovY/2) / z texture units from the centre, whatever the range.
// skinlab's artistic kernel (outermost tap at width_mm for more than 20 taps) at the converted width lands there.
TEST(ThesisWidth, SeparableReplaysTheThesisStep) {
    for (const View v : kViews) {
        const double t = v.tanHalfFov();
        for (const double kernelRange : {3.0, 2.0}) {
            const double stepUv = v.sssWidth * (1.0 / t) / v.z * 0.7 / kernelRange; // per kernel unit
            const double thesisEdgePixels = kernelRange * stepUv * v.height;        // vertical pass
            const double edgePixels = test::artisticEdgePixels(
                widthMmFromThesisSssWidth(v.sssWidth, v.mmPerUnit, ThesisBlurShader::Separable), v);
            EXPECT_NEAR(edgePixels, thesisEdgePixels, 1e-9 * thesisEdgePixels) << "sssWidth " << v.sssWidth;
        }
    }
}

// The thesis' sum-of-Gaussians passes step √Δv · 0.1 · sssWidth · (1 / tan(fovY/2)) / z · dir / 3 per tap offset,
// offsets in [−1, 1] = ±3σ: a stage's σ lies at √Δv · 0.1 · sssWidth · cot(fovY/2) / (9 z) texture units. skinlab's
// gaussian-sum stages at the converted width have that σ in pixels, stage by stage (d'Eon's incremental variances).
TEST(ThesisWidth, GaussianSumReplaysTheThesisStep) {
    for (const View v : kViews) {
        const double t = v.tanHalfFov();
        SssParams params;
        params.method = methodId("gaussian-sum");
        params.widthMm = widthMmFromThesisSssWidth(v.sssWidth, v.mmPerUnit, ThesisBlurShader::GaussianSum);
        const Kernel kernel = makeKernel(params);
        ASSERT_EQ(kernel.stages.size(), 6u);
        const double fPx = 0.5 * v.height / t;
        const double profileVariances[] = {0.0064, 0.0484, 0.187, 0.567, 1.99, 7.41}; // mm², d'Eon
        double previous = 0.0;
        for (std::size_t i = 0; i < 6; ++i) {
            const double deltaV = profileVariances[i] - previous;
            previous = profileVariances[i];
            const double thesisSigmaPixels = std::sqrt(deltaV) * 0.1 * v.sssWidth * (1.0 / t) / (9.0 * v.z) * v.height;
            const double sigmaPixels = std::sqrt(kernel.stages[i].varianceMm2) * fPx / (v.mmPerUnit * v.z);
            EXPECT_NEAR(sigmaPixels, thesisSigmaPixels, 1e-9 * thesisSigmaPixels) << "stage " << i;
        }
    }
}
