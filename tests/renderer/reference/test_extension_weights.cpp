// The extension weights (renderer/sss/extension_weights.h): CIELAB against published values, the auxiliary image's
// distance invariance, the fallback, the curvature strategies.
#include "common/error.h"
#include "renderer/sss/extension_weights.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace skinlab::renderer::sss;

namespace {
void expectLab(const glm::vec3& rgb, const glm::vec3& expected) {
    const glm::vec3 lab = linearRec709ToLab(rgb);
    // Published values have 4 decimals; float arithmetic of the 3×3 matrix and cbrt adds < 1e-3.
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(lab[i], expected[i], 2e-3) << "component " << i;
}
} // namespace

TEST(ExtensionWeights, LabOfTheSrgbPrimariesAndWhite) {
    // Reference: B. Lindbloom's calculator (sRGB, D65, no adaptation), which uses the same CIE constants.
    expectLab({1, 1, 1}, {100.0f, 0.0f, 0.0f});
    expectLab({1, 0, 0}, {53.2408f, 80.0925f, 67.2032f});
    expectLab({0, 1, 0}, {87.7347f, -86.1827f, 83.1793f});
    expectLab({0, 0, 1}, {32.2970f, 79.1875f, -107.8602f});
    expectLab({0, 0, 0}, {0.0f, 0.0f, 0.0f});
    // Grey 0.18: L = 116 · 0.18^(1/3) − 16 = 49.4961 (neutral: a = b = 0).
    expectLab({0.18f, 0.18f, 0.18f}, {49.4961f, 0.0f, 0.0f});
    // Dark grey below the linear segment's knee ((6/29)³ = 0.008856): L = 903.3 · Y.
    expectLab({0.005f, 0.005f, 0.005f}, {4.5165f, 0.0f, 0.0f});
}

TEST(ExtensionWeights, LabWeightIsExponentialInDeltaE) {
    const glm::vec3 a{50, 0, 0}, b{50, 3, 4}; // ΔE*ab = 5
    EXPECT_FLOAT_EQ(labWeight(a, a, 0.09f), 1.0f);
    EXPECT_FLOAT_EQ(labWeight(a, b, 0.0f), 1.0f); // β = 0: off
    EXPECT_NEAR(labWeight(a, b, 0.09f), std::exp(-0.45f), 1e-6f);
    EXPECT_NEAR(labWeight(a, b, 0.5f), std::exp(-2.5f), 1e-6f);
    // Skin against the bleed scene's green-blue paint: the weight nearly vanishes at the thesis's β = 0.09.
    const float skinToPaint =
        labWeight(linearRec709ToLab({0.6f, 0.4f, 0.3f}), linearRec709ToLab({0.05f, 0.6f, 0.8f}), 0.09f);
    EXPECT_LT(skinToPaint, 0.01f);
}

TEST(ExtensionWeights, AuxiliaryImageIsDistanceInvariant) {
    const glm::vec3 normal = glm::normalize(glm::vec3(0.3f, 0.2f, 1.0f));
    const glm::vec3 direction = glm::normalize(glm::vec3(0.2f, -0.1f, -1.0f));
    const float near = auxiliaryValue(direction * 10.0f, normal);
    const float far = auxiliaryValue(direction * 1000.0f, normal);
    EXPECT_NEAR(near, far, 1e-6f);
    // F = cos φ_i / cos φ_j: on the view axis, facing the camera, F = 1.
    EXPECT_NEAR(auxiliaryValue({0, 0, -5}, {0, 0, 1}), 1.0f, 1e-6f);
    // Tilted by 60° on the view axis: F = 1 / cos 60° = 2.
    EXPECT_NEAR(auxiliaryValue({0, 0, -5}, {std::sin(1.0471976f), 0, std::cos(1.0471976f)}), 2.0f, 1e-5f);
    // Off axis by 30° with the normal towards the viewer: F = cos 30°.
    const glm::vec3 offAxis{std::sin(0.5235988f), 0, -std::cos(0.5235988f)};
    EXPECT_NEAR(auxiliaryValue(offAxis * 7.0f, -offAxis), std::cos(0.5235988f), 1e-5f);
    // Grazing and back-facing normals are clamped: F ≤ 1 / kAuxiliaryMinCosine.
    EXPECT_NEAR(auxiliaryValue({0, 0, -5}, {1, 0, 0}), 1.0f / kAuxiliaryMinCosine, 1e-3f);
    EXPECT_NEAR(auxiliaryValue({0, 0, -5}, {0, 0, -1}), 1.0f / kAuxiliaryMinCosine, 1e-3f);
    // Albedo-grey modulation multiplies.
    EXPECT_NEAR(auxiliaryValue({0, 0, -5}, {0, 0, 1}, 0.4f), 0.4f, 1e-6f);
}

TEST(ExtensionWeights, AuxiliaryWeightAndFallback) {
    EXPECT_FLOAT_EQ(auxiliaryWeight(1.0f, 1.0f, 10.0f), 1.0f);
    EXPECT_NEAR(auxiliaryWeight(1.0f, 1.3f, 10.0f), std::exp(-3.0f), 1e-6f);
    EXPECT_FLOAT_EQ(auxiliaryWeight(1.0f, 5.0f, 0.0f), 1.0f);
    const glm::vec3 centre{0.2f, 0.3f, 0.4f};
    // Normal case: the weighted mean.
    const glm::vec3 mean = resolveWeightedSum(glm::vec3(0.5f, 0.5f, 0.5f), 0.5f, centre);
    EXPECT_NEAR(mean.x, 1.0f, 1e-6f);
    // Every tap rejected: the unblurred centre, never black.
    const glm::vec3 fallback = resolveWeightedSum(glm::vec3(0.0f), 0.0f, centre);
    EXPECT_EQ(fallback, centre);
    EXPECT_EQ(resolveWeightedSum(glm::vec3(1e-6f), 0.5f * kMinimumWeightSum, centre), centre);
}

TEST(ExtensionWeights, CurvatureStrategies) {
    // A sphere of radius 20 mm (the reference radius) is fully curved; 80 mm gives c = 0.25; a plane 0.
    EXPECT_FLOAT_EQ(normalisedCurvature(1.0f / 20.0f, 1.0f), 1.0f);
    EXPECT_FLOAT_EQ(normalisedCurvature(1.0f / 80.0f, 1.0f), 0.25f);
    EXPECT_FLOAT_EQ(normalisedCurvature(0.0f, 1.0f), 0.0f);
    EXPECT_FLOAT_EQ(normalisedCurvature(-1.0f, 1.0f), 0.0f); // concave (negative) is clamped
    // Units: 1 unit = 10 mm, curvature 1/8 per unit = 1/80 per mm.
    EXPECT_FLOAT_EQ(normalisedCurvature(1.0f / 8.0f, 10.0f), 0.25f);

    EXPECT_FLOAT_EQ(curvatureWidthScale(CurvatureStrategy::Off, 0.3f, 0.5f), 1.0f);
    EXPECT_FLOAT_EQ(curvatureWidthScale(CurvatureStrategy::Increase, 0.3f, 0.5f), 1.3f);
    EXPECT_FLOAT_EQ(curvatureWidthScale(CurvatureStrategy::Reduce, 0.3f, 0.5f), 0.3f);
    EXPECT_FLOAT_EQ(curvatureWidthScale(CurvatureStrategy::ReduceFloor, 0.3f, 0.5f), 0.65f);
    // Flat areas: reduce loses all SSS, reduce-floor keeps the floor.
    EXPECT_FLOAT_EQ(curvatureWidthScale(CurvatureStrategy::Reduce, 0.0f, 0.5f), 0.0f);
    EXPECT_FLOAT_EQ(curvatureWidthScale(CurvatureStrategy::ReduceFloor, 0.0f, 0.5f), 0.5f);
    // Fully curved: reduce and reduce-floor give the unmodified width.
    EXPECT_FLOAT_EQ(curvatureWidthScale(CurvatureStrategy::ReduceFloor, 1.0f, 0.5f), 1.0f);
    EXPECT_FLOAT_EQ(transmittanceCurvatureScale(0.5f), 1.5f);
}

TEST(ExtensionWeights, CurvatureNames) {
    for (const auto& name : curvatureStrategyNames())
        EXPECT_EQ(curvatureStrategyName(curvatureStrategyFromName(name, "scene.toml")), name);
    try {
        curvatureStrategyFromName("more", "scene.toml");
        FAIL() << "no exception";
    } catch (const skinlab::InputError& e) {
        EXPECT_STREQ(e.what(), "scene.toml: sss.curvature: 'more' is not one of: off, increase, reduce, reduce-floor");
    }
}
