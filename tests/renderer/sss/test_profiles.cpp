// Diffusion profiles and their marginals against closed forms and numerical integration (d'Eon & Luebke, GPU Gems 3 ch. 14).
#include "renderer/sss/burley_profile.h"
#include "renderer/sss/gaussian_sum_profile.h"
#include "renderer/sss/materials.h"
#include "renderer/sss/numerical_integration.h"
#include "renderer/sss/radial_marginal.h"

#include <cmath>
#include <gtest/gtest.h>
#include <numbers>

using namespace skinlab::renderer::sss;

TEST(Profiles, DeonWeightsSumToOnePerChannelWithPublishedBlue) {
    double sum[3] = {0, 0, 0};
    for (const auto& lobe : deonSkinLobes())
        for (int c = 0; c < 3; ++c) sum[c] += lobe.weight[c];
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], 1.0, 1e-12) << "channel " << c;
    EXPECT_DOUBLE_EQ(deonSkinLobes()[0].weight[2], 0.649); // not the thesis text's 0.69
}

TEST(Profiles, MarginalOfGaussianIsTheOneDimensionalGaussian) {
    // Separability: ∫ G(v, √(x²+y²)) dy = exp(−x²/2v)/√(2πv), here by numerical line integration.
    for (double v : {0.0064, 0.187, 1.99, 7.41}) {
        for (double x : {0.0, 0.05, 0.3, 1.0, 3.0}) {
            const double numerical = marginalOfRadial([&](double r) { return gaussian2d(v, r); }, x, std::sqrt(v));
            const double expected = gaussian1d(v, x);
            EXPECT_NEAR(numerical, expected, 1e-8 * std::max(1.0, expected)) << "v=" << v << " x=" << x;
        }
    }
}

TEST(Profiles, GaussianSumCumulativeMatchesIntegratedDensity) {
    GaussianSumProfile deon(deonSkinLobes(), "d'Eon");
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(deon.cumulative(c, 0.0), 0.5, 1e-12);
        for (double x : {0.1, 0.7, 2.0, 5.0}) {
            const double integral = 0.5 + integrate([&](double t) { return deon.density(c, t); }, 0.0, x, 1e-13);
            EXPECT_NEAR(deon.cumulative(c, x), integral, 1e-9) << "channel " << c << " x=" << x;
        }
    }
}

TEST(Profiles, BurleyRadialProfileHasUnitEnergyAndItsPublishedCdf) {
    BurleyProfile burley({0.5, 0.2, 0.1}, "test");
    for (int c = 0; c < 3; ++c) {
        const double d = burley.shapeMm()[c];
        const double energy = integrateToInfinity(
            [&](double r) { return 2.0 * std::numbers::pi * r * burley.radial(c, r); }, 0.0, 3.0 * d, 1e-13);
        EXPECT_NEAR(energy, 1.0, 1e-8) << "channel " << c;
        const double r = 1.3 * d;
        const double partial =
            integrate([&](double t) { return 2.0 * std::numbers::pi * t * burley.radial(c, t); }, 0.0, r, 1e-13);
        EXPECT_NEAR(burley.radialCumulative(c, r), partial, 1e-9);
    }
}

TEST(Profiles, BurleyBesselMarginalMatchesNumericalIntegration) {
    // a(x) = [K0(x/d) + K0(x/3d)] / (4πd) against 2∫_0^∞ R(√(x²+u²)) du.
    BurleyProfile burley({0.4445, 0.0987, 0.0595}, "skin-like");
    for (int c = 0; c < 3; ++c) {
        for (double x : {0.001, 0.01, 0.05, 0.2, 0.8, 2.0, 6.0}) {
            const double closed = burley.density(c, x);
            const double numerical = burley.densityNumerical(c, x);
            EXPECT_NEAR(numerical / closed, 1.0, 1e-6) << "channel " << c << " x=" << x;
        }
        EXPECT_TRUE(std::isinf(burley.density(c, 0.0)));
    }
}

TEST(Profiles, BurleyMarginalCumulativeAndMomentMatchTheDensity) {
    BurleyProfile burley({0.4, 0.1, 0.06}, "test");
    for (int c = 0; c < 3; ++c) {
        const double d = burley.shapeMm()[c];
        EXPECT_NEAR(burley.cumulative(c, 0.0), 0.5, 1e-12);
        EXPECT_NEAR(burley.cumulative(c, 200.0 * d), 1.0, 1e-9);
        for (double x : {0.3 * d, d, 4.0 * d}) {
            // ∫_0^x a(t) dt with the log singularity at 0 handled by t = x·s² (dt = 2xs ds).
            const double integral = integrate(
                [&](double s) { return s == 0.0 ? 0.0 : burley.density(c, x * s * s) * 2.0 * x * s; }, 0.0, 1.0, 1e-13);
            EXPECT_NEAR(burley.cumulative(c, x) - 0.5, integral, 1e-8) << "channel " << c << " x=" << x;
            // Two independent routes: ∫K0 (closed form, tabulated) and the strip energy of the radial profile.
            EXPECT_NEAR(burley.cumulative(c, x), burley.cumulativeByStrip(c, x), 1e-8) << "channel " << c;
        }
        const double moment =
            2.0 * integrateToInfinity([&](double t) { return t == 0.0 ? 0.0 : t * t * burley.density(c, t); }, 0.0,
                                      3.0 * d, 1e-13);
        EXPECT_NEAR(moment / burley.secondMoment(c), 1.0, 1e-6);
    }
}

TEST(Profiles, TransmittanceIsOneAtZeroThicknessAndDecreases) {
    const auto t0 = deonTransmittance(0.0);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(t0[c], 1.0, 1e-12);
    const auto t1 = deonTransmittance(1.0);
    EXPECT_GT(t1[0], t1[1]); // red travels farther than green and blue
    EXPECT_GT(t1[1], t1[2]);
    EXPECT_DOUBLE_EQ(burleyTransmittance(0.5, 0.0), 1.0);
}

TEST(Materials, BurleySkinMatchesDeonSecondMoment) {
    GaussianSumProfile deon(deonSkinLobes(), "d'Eon");
    BurleyProfile burley(burleyShapeMm("skin"), "skin");
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(burley.secondMoment(c), deon.secondMoment(c), 1e-12);
}

TEST(Materials, MeasuredMediaGiveRedderLongerScatteringForSkin) {
    // Hand computation for Jensen's Skin1 red channel (σs' = 0.74, σa = 0.032 per mm, η = 1.3):
    // α' = 0.74/0.772, ℓd = 1/√(3·0.032·0.772) = 3.6733 mm, Rd = 0.43594, s = 1.85 − Rd + 7|Rd − 0.8|³ = 1.75183,
    // d = ℓd / s = 2.0968 mm.
    const auto d = burleyShapeMm("skin1");
    EXPECT_NEAR(d[0], 2.0968, 2e-3);
    EXPECT_GT(d[0], d[1]);
    EXPECT_GT(d[1], d[2]);
    for (const auto& name : materialNames())
        for (double v : burleyShapeMm(name)) EXPECT_GT(v, 0.0) << name;
    EXPECT_NEAR(dipoleDiffuseReflectance(0.74 / 0.772, 1.3), 0.43594, 1e-4);
}
