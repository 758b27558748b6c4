// The object-space reference convolution (renderer/reference/surface_convolution.h): the profile's radial CDF,
// the analytic response to a step, convergence with sample density, skin-only scattering.
#include "common/error.h"
#include "renderer/sss/radial_profile.h"
#include "renderer/reference/surface_convolution.h"
#include "renderer/reference/tessellation.h"
#include "renderer/scene/builtin_geometry.h"
#include "renderer/sss/burley_profile.h"
#include "renderer/sss/gaussian_sum_profile.h"
#include "renderer/sss/materials.h"
#include "test_models.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

using namespace skinlab::renderer;
using namespace skinlab::renderer::reference;
using skinlab::renderer::sss::makeRadialProfile;
using skinlab::renderer::sss::RadialProfile;

namespace {
sss::SssParams profileParams(const std::string& profile, double widthMm = 3.0) {
    sss::SssParams params;
    params.profile = profile;
    params.widthMm = widthMm;
    return params;
}

// ∫_0^r 2πs R(s) ds by the midpoint rule on a fine grid (R finite away from 0).
double integrateRadial(const RadialProfile& profile, int channel, double rMm) {
    const int steps = 200000;
    const double h = rMm / steps;
    double sum = 0.0;
    for (int i = 0; i < steps; ++i) {
        const double s = (i + 0.5) * h;
        sum += 2.0 * std::numbers::pi * s * profile.radial(channel, s) * h;
    }
    return sum;
}

// builtin:halo (the sphere, radius 40 mm, and its backdrop) tessellated to 1 mm edges.
SurfaceSamples haloSphereSamples() {
    return gatherSurfaceSamples(tessellateSkin(makeHaloScene(200.0f), 1.0f, 1.0f), 1.0f);
}

// Every stride-th skin sample on the sphere (not the backdrop).
std::vector<std::uint32_t> haloSphereReceivers(const SurfaceSamples& samples, std::uint32_t stride) {
    std::vector<std::uint32_t> receivers;
    for (std::uint32_t i = 0; i < samples.size(); i += stride)
        if (samples.skin[i] && glm::length(samples.positionMm[i]) < kHaloSphereRadiusMm + 0.5f) receivers.push_back(i);
    return receivers;
}

// Step irradiance E = 1 for x > stepX, 0 for x < stepX (stepX between two columns of samples); albedo 1.
std::vector<glm::vec3> stepIrradiance(const SurfaceSamples& samples, float stepX) {
    std::vector<glm::vec3> irradiance(samples.size());
    for (std::size_t i = 0; i < samples.size(); ++i)
        irradiance[i] = glm::vec3(samples.positionMm[i].x > stepX ? 1.0f : 0.0f);
    return irradiance;
}

double maxDifference(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b,
                     const std::vector<std::uint32_t>& at) {
    double worst = 0.0;
    for (const std::uint32_t i : at)
        for (int c = 0; c < 3; ++c) worst = std::max(worst, double(std::abs(a[i][c] - b[i][c])));
    return worst;
}

double rmsDifference(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b,
                     const std::vector<std::uint32_t>& at) {
    double sum = 0.0;
    for (const std::uint32_t i : at)
        for (int c = 0; c < 3; ++c) sum += double(a[i][c] - b[i][c]) * double(a[i][c] - b[i][c]);
    return std::sqrt(sum / (3.0 * double(at.size())));
}
} // namespace

TEST(RadialProfile, CumulativeIsTheIntegralOfTheRadialDensity) {
    for (const double width : {3.0, 1.5}) {
        const auto deon = makeRadialProfile(profileParams("deon", width));
        for (int c = 0; c < 3; ++c)
            for (const double r : {0.5, 2.0, 6.0})
                EXPECT_NEAR(deon->cumulative(c, r), integrateRadial(*deon, c, r), 1e-6) << c << " " << r;
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(deon->cumulative(c, 1e3), 1.0, 1e-12);
    }
    // Burley: the 1/r centre is integrable; compare away from 0 (difference of the cumulative between 0.5 and 4 mm).
    const auto burley = makeRadialProfile(profileParams("burley"));
    for (int c = 0; c < 3; ++c) {
        const double outer = integrateRadial(*burley, c, 4.0) - integrateRadial(*burley, c, 0.5);
        EXPECT_NEAR(burley->cumulative(c, 4.0) - burley->cumulative(c, 0.5), outer, 1e-4) << c;
    }
}

TEST(RadialProfile, WidthScalesDistancesAndTheCutoff) {
    const auto base = makeRadialProfile(profileParams("deon", 3.0));
    const auto wide = makeRadialProfile(profileParams("deon", 6.0));
    EXPECT_NEAR(wide->cumulative(0, 4.0), base->cumulative(0, 2.0), 1e-12);
    const double cutoff = base->cutoffRadiusMm(1e-3);
    // d'Eon red: 0.078 exp(−r²/(2 · 7.41)) = 1e-3 at r = √(2 · 7.41 · ln 78) = 8.04 mm (the other lobes add < 1e-6).
    EXPECT_NEAR(cutoff, std::sqrt(2.0 * 7.41 * std::log(78.0)), 0.01);
    EXPECT_NEAR(wide->cutoffRadiusMm(1e-3), 2.0 * cutoff, 1e-6);
}

TEST(RadialProfile, TabulatedProfilesAreRejected) {
    try {
        makeRadialProfile(profileParams("file:/tmp/Skin1_PreInt_DISCSEP.bn"));
        FAIL() << "no exception";
    } catch (const skinlab::InputError& e) {
        EXPECT_STREQ(e.what(), "sss.profile: 'file:/tmp/Skin1_PreInt_DISCSEP.bn' has no radial form for the reference "
                               "method (use deon or burley)");
    }
}

// On a flat plane a step irradiance convolves to the marginal's CDF across the step: out(x) = ∫_{x'>0} a(x − x')
// dx' = P(X < x) = cumulative(x) of the 1-D marginal (d'Eon & Luebke, GPU Gems 3 ch. 14).
class StepResponse : public ::testing::TestWithParam<std::string> {};

TEST_P(StepResponse, EqualsTheMarginalCdf) {
    const std::string profileName = GetParam();
    const sss::SssParams params = profileParams(profileName);
    const auto profile = makeRadialProfile(params);
    std::unique_ptr<sss::Marginal> marginal;
    if (profileName == "deon") marginal = std::make_unique<sss::GaussianSumProfile>(sss::deonSkinLobes(), "deon");
    else marginal = std::make_unique<sss::BurleyProfile>(sss::burleyShapeMm("skin"), "burley");

    // A 40 mm square (half-width 20 mm > 2 cutoffs, so receivers near the centre line see an infinite plane),
    // tessellated to 64, 128 and 256 cells per side (0.63, 0.31, 0.16 mm).
    std::vector<double> worstErrors;
    for (const float edge : {0.9f, 0.45f, 0.225f}) {
        TessellationStatistics statistics;
        const Model plane = tessellateSkin(test_models::makeSquare(40.0f), edge, 1.0f, &statistics);
        // Samples sit on a grid of spacing h; the step lies halfway between two columns, on the boundary of the
        // samples' cells, so the piecewise-constant irradiance the samples stand for has its step exactly there.
        const float spacing = 40.0f / float(1 << statistics.rounds);
        const float stepX = 0.5f * spacing;
        const SurfaceSamples samples = gatherSurfaceSamples(plane, 1.0f);
        std::vector<std::uint32_t> receivers; // the samples on the line y = 0 with |x| ≤ 5 mm
        for (std::uint32_t i = 0; i < samples.size(); ++i)
            if (std::abs(samples.positionMm[i].y) < 1e-4f && std::abs(samples.positionMm[i].x) <= 5.0f)
                receivers.push_back(i);
        ASSERT_GT(receivers.size(), 15u);
        ConvolutionReport report;
        const auto out = convolveSurface(samples, stepIrradiance(samples, stepX), *profile, {}, &receivers, &report);
        EXPECT_EQ(report.receivers, receivers.size());
        double worst = 0.0, worstX = 0.0;
        for (const std::uint32_t i : receivers) {
            const double x = samples.positionMm[i].x;
            for (int c = 0; c < 3; ++c) {
                const double expected = marginal->cumulative(c, x - stepX);
                if (std::abs(out[i][c] - expected) > worst) {
                    worst = std::abs(out[i][c] - expected);
                    worstX = x;
                }
            }
        }
        std::printf("step response (%s, edge %.3f mm): worst |out − CDF| = %.5f at x = %.3f mm, %zu receivers, "
                    "cutoff %.3f mm, %.0f sources each\n",
                    profileName.c_str(), edge, worst, worstX, receivers.size(), report.cutoffRadiusMm,
                    report.meanSources);
        worstErrors.push_back(worst);
    }
    // The error shrinks with the spacing (measured: d'Eon 0.019, 0.017, 0.013; Burley 0.016, 0.015, 0.009). What
    // is left at 0.16 mm is the point quadrature of the lobes narrower than the spacing next to the step (d'Eon's
    // σ = 0.08 mm lobe, Burley's cusp), which the receiver's own disc carries whole: 1.5 % of the step height.
    for (std::size_t k = 1; k < worstErrors.size(); ++k) EXPECT_LT(worstErrors[k], worstErrors[k - 1]) << k;
    EXPECT_LT(worstErrors.back(), 0.015);
}

INSTANTIATE_TEST_SUITE_P(Profiles, StepResponse, ::testing::Values("deon", "burley"),
                         [](const auto& param) { return std::string(param.param); });

TEST(SurfaceConvolution, ConvergesAsSampleDensityGrows) {
    // builtin:halo's skin sphere (radius 40 mm) lit by a directional light: E = max(0, n · L), albedo of skin.
    // Values at the original vertices (kept by the tessellation) for edge lengths 4 (untouched), 2, 1, 0.5 mm.
    const Model halo = makeHaloScene(200.0f);
    const glm::vec3 light = glm::normalize(glm::vec3(0.45f, 0.45f, 0.77f));
    const auto profile = makeRadialProfile(profileParams("deon"));
    std::vector<std::uint32_t> receivers;
    for (std::uint32_t i = 0; i < halo.vertices.size(); i += 7)
        if (glm::length(halo.vertices[i].position) < kHaloSphereRadiusMm + 1.0f) receivers.push_back(i); // sphere only
    std::vector<std::vector<glm::vec3>> results;
    for (const float edge : {4.0f, 2.0f, 1.0f, 0.5f}) {
        const Model fine = tessellateSkin(halo, edge, 1.0f);
        const SurfaceSamples samples = gatherSurfaceSamples(fine, 1.0f);
        std::vector<glm::vec3> irradiance(samples.size());
        for (std::size_t i = 0; i < samples.size(); ++i)
            irradiance[i] = glm::vec3(std::max(0.0f, glm::dot(samples.normal[i], light)));
        results.push_back(convolveSurface(samples, irradiance, *profile, {}, &receivers));
    }
    // The adaptive tessellation refines each triangle only as far as the edge length asks, so successive densities
    // are not nested 1 → 4 everywhere; convergence is measured against the finest result (0.5 mm): the difference
    // must shrink at every refinement.
    std::vector<double> rms, worst;
    for (std::size_t k = 0; k + 1 < results.size(); ++k) {
        rms.push_back(rmsDifference(results[k], results.back(), receivers));
        worst.push_back(maxDifference(results[k], results.back(), receivers));
        std::printf(
            "convergence: edge %.2g mm vs 0.5 mm: RMS difference %.6f, max %.6f; vs the next density: RMS %.6f\n",
            4.0 / (1 << k), rms.back(), worst.back(), rmsDifference(results[k], results[k + 1], receivers));
    }
    for (std::size_t k = 1; k < rms.size(); ++k) EXPECT_LT(rms[k], rms[k - 1]) << k;
    EXPECT_LT(worst.back(), 0.01); // radiance ≤ albedo < 1: 1 mm is within 1 % of white of 0.5 mm
}

TEST(SurfaceConvolution, TheOwnShareSplitsOffTheNearFieldExactly) {
    // builtin:halo's sphere at 1 mm edges under a light with a step (a spot's hard edge) and the convex-surface
    // gain: with the own term alone, far + share · E·α equals the whole sum at every receiver; with the near field
    // of half the edge length (as the reference draws), each share lies in [0, 1 + L_c / R] and holds at least the weight of
    // d'Eon's σ = 80 µm lobe (0.233 in red, 0.455 green, 0.649 blue), also at the poles' small triangles and along
    // the seam's twin vertices. Samples that are not convolved return 0 with share 1.
    const SurfaceSamples samples = haloSphereSamples();
    const auto profile = makeRadialProfile(profileParams("deon"));
    const std::vector<std::uint32_t> receivers = haloSphereReceivers(samples, 5);
    ASSERT_GT(receivers.size(), 100u);
    std::vector<glm::vec3> irradiance(samples.size());
    for (std::size_t i = 0; i < samples.size(); ++i)
        irradiance[i] = samples.positionMm[i].x > 3.0f ? glm::vec3(1.0f, 0.9f, 0.8f) : glm::vec3(0.05f);
    ConvolutionSettings settings;
    settings.convexityMm = {0.88, 0.32, 0.28};
    const auto whole = convolveSurface(samples, irradiance, *profile, settings, &receivers);
    std::vector<glm::vec3> share;
    const auto far = convolveSurface(samples, irradiance, *profile, settings, &receivers, nullptr, &share);
    ASSERT_EQ(share.size(), samples.size());
    const glm::vec3 narrowLobe(0.233f, 0.455f, 0.649f);
    double worst = 0.0;
    for (const std::uint32_t i : receivers)
        for (int c = 0; c < 3; ++c) {
            const double recombined = far[i][c] + share[i][c] * irradiance[i][c] * samples.albedo[i][c];
            worst = std::max(worst, std::abs(recombined - whole[i][c]));
        }
    EXPECT_LT(worst, 1e-6);
    settings.nearFieldMm = 0.5;
    std::vector<glm::vec3> nearShare;
    convolveSurface(samples, irradiance, *profile, settings, &receivers, nullptr, &nearShare);
    for (const std::uint32_t i : receivers)
        for (int c = 0; c < 3; ++c) {
            EXPECT_GE(nearShare[i][c], narrowLobe[c]) << i << " " << c;
            // at most all of the weight, times the convex-surface gain 1 + L_c / R
            EXPECT_LE(nearShare[i][c],
                      1.0 + settings.convexityMm[static_cast<std::size_t>(c)] / kHaloSphereRadiusMm + 1e-3)
                << i << " " << c;
        }
    std::uint32_t untouched = 0;
    while (std::find(receivers.begin(), receivers.end(), untouched) != receivers.end()) ++untouched;
    EXPECT_EQ(far[untouched], glm::vec3(0.0f));
    EXPECT_EQ(share[untouched], glm::vec3(1.0f));
}

TEST(SurfaceConvolution, OnlySkinScattersAndReceives) {
    // builtin:bleed: skin patch with two paint squares. Light on the paint must not reach the skin, and the paint's
    // own output is its unblurred E·α.
    const Model bleed = tessellateSkin(makeBleedScene(), 2.0f, 1.0f);
    const SurfaceSamples samples = gatherSurfaceSamples(bleed, 1.0f);
    const auto profile = makeRadialProfile(profileParams("deon"));
    std::vector<glm::vec3> dark(samples.size()), bright(samples.size());
    for (std::size_t i = 0; i < samples.size(); ++i) {
        dark[i] = glm::vec3(1.0f);
        bright[i] = samples.skin[i] ? glm::vec3(1.0f) : glm::vec3(1000.0f);
    }
    ConvolutionSettings absorbs;
    absorbs.nonSkin = NonSkin::Absorbs;
    const auto a = convolveSurface(samples, dark, *profile, absorbs);
    const auto b = convolveSurface(samples, bright, *profile, absorbs);
    const auto returned = convolveSurface(samples, dark, *profile); // NonSkin::Returns, the default
    for (std::size_t i = 0; i < samples.size(); ++i) {
        if (samples.skin[i]) {
            ASSERT_EQ(a[i], b[i]) << i; // bit-identical: no non-skin source enters the light
            // NonSkin::Returns: uniform irradiance on uniformly coloured skin stays E·α after renormalisation, at
            // edges too; NonSkin::Absorbs darkens skin next to the paint, never brightens it.
            for (int c = 0; c < 3; ++c) {
                ASSERT_NEAR(returned[i][c], samples.albedo[i][c], 1e-5f) << i;
                ASSERT_LE(a[i][c], samples.albedo[i][c] + 1e-5f) << i;
            }
        } else {
            ASSERT_EQ(b[i], glm::vec3(1000.0f) * samples.albedo[i]) << i;
        }
    }
}

TEST(SurfaceConvolution, NonSkinNeighboursAbsorbTheLightCarriedToThem) {
    // A plane, skin for x > x0 and another material for x < x0, uniformly lit, albedo 1. With NonSkin::Absorbs the
    // light the profile carries across x0 leaves the skin, as a path tracer's random walk ends where the skin's
    // medium ends: out(x) = the share of the profile on the skin side = the 1-D marginal's CDF at x − x0 (the same
    // quadrature as StepResponse). With NonSkin::Returns it is handed back: out = 1 everywhere.
    TessellationStatistics statistics;
    const Model plane = tessellateSkin(test_models::makeSquare(40.0f), 0.225f, 1.0f, &statistics);
    const float spacing = 40.0f / float(1 << statistics.rounds);
    const float stepX = 0.5f * spacing;
    SurfaceSamples samples = gatherSurfaceSamples(plane, 1.0f);
    std::vector<std::uint32_t> receivers;
    for (std::uint32_t i = 0; i < samples.size(); ++i) {
        samples.albedo[i] = glm::vec3(1.0f);
        samples.skin[i] = samples.positionMm[i].x > stepX ? 1 : 0;
        if (samples.skin[i] && std::abs(samples.positionMm[i].y) < 1e-4f && samples.positionMm[i].x <= 5.0f)
            receivers.push_back(i);
    }
    ASSERT_GT(receivers.size(), 15u);
    const std::vector<glm::vec3> uniform(samples.size(), glm::vec3(1.0f));
    const auto profile = makeRadialProfile(profileParams("deon"));
    const sss::GaussianSumProfile marginal(sss::deonSkinLobes(), "deon");
    ConvolutionSettings absorbs;
    absorbs.nonSkin = NonSkin::Absorbs;
    const auto absorbed = convolveSurface(samples, uniform, *profile, absorbs, &receivers);
    const auto returned = convolveSurface(samples, uniform, *profile, {}, &receivers); // NonSkin::Returns
    double worst = 0.0, nearest = 2.0;
    for (const std::uint32_t i : receivers) {
        const double x = samples.positionMm[i].x;
        for (int c = 0; c < 3; ++c) {
            worst = std::max(worst, std::abs(absorbed[i][c] - marginal.cumulative(c, x - stepX)));
            EXPECT_NEAR(returned[i][c], 1.0, 1e-5) << x;
        }
        if (x - stepX < spacing) nearest = std::min(nearest, double(absorbed[i][1]));
    }
    std::printf("absorbing neighbours: worst |out − CDF| = %.5f over %zu receivers; green next to the boundary %.3f\n",
                worst, receivers.size(), nearest);
    EXPECT_LT(worst, 0.02);
    EXPECT_GT(nearest, 0.5); // half the profile lies beyond the boundary, minus what the nearest spacing keeps
    EXPECT_LT(nearest, 0.9);
}

TEST(SurfaceConvolution, ConvexityGainFollowsTheCurvature) {
    // builtin:halo's sphere (radius 40 mm) under uniform irradiance: the kernel-weighted curvature is 1/R, so the
    // output is α (1 + L_c / R); with L = 0 it is α. A flat plane keeps α whatever L.
    const SurfaceSamples samples = haloSphereSamples();
    const auto profile = makeRadialProfile(profileParams("deon"));
    const std::vector<std::uint32_t> receivers = haloSphereReceivers(samples, 11);
    ASSERT_GT(receivers.size(), 100u);
    const std::vector<glm::vec3> uniform(samples.size(), glm::vec3(1.0f));
    ConvolutionSettings convex;
    convex.convexityMm = {2.0, 1.0, 0.0};
    const auto plain = convolveSurface(samples, uniform, *profile, {}, &receivers);
    const auto gained = convolveSurface(samples, uniform, *profile, convex, &receivers);
    double worst = 0.0;
    for (const std::uint32_t i : receivers)
        for (int c = 0; c < 3; ++c) {
            const double expected = 1.0 + convex.convexityMm[static_cast<std::size_t>(c)] / kHaloSphereRadiusMm;
            if (std::abs(gained[i][c] / plain[i][c] - expected) > worst) {
                worst = std::abs(gained[i][c] / plain[i][c] - expected);
                if (worst > 0.002)
                    std::printf("at (%.2f, %.2f, %.2f) channel %d: %.4f\n", samples.positionMm[i].x,
                                samples.positionMm[i].y, samples.positionMm[i].z, c, gained[i][c] / plain[i][c]);
            }
            EXPECT_NEAR(plain[i][c], samples.albedo[i][c], 1e-4) << i;
        }
    std::printf("convexity gain on a 40 mm sphere: worst |gain − (1 + L/R)| = %.5f over %zu receivers\n", worst,
                receivers.size());
    EXPECT_LT(worst, 0.002); // L/R = 0.05 in red: the estimate of 1/R within 4 %

    // builtin:ear's 2.5 mm fin: where a receiver's kernel reaches the far side, whose light the through-light gain
    // carries, the convexity term fades out; its rounded rim (about 1 mm radius) counts as 20 mm at most.
    const Model ear = tessellateSkin(makeEarScene(2.5f), 1.0f, 1.0f);
    const SurfaceSamples fin = gatherSurfaceSamples(ear, 1.0f);
    const std::vector<glm::vec3> finUniform(fin.size(), glm::vec3(1.0f));
    const auto finPlain = convolveSurface(fin, finUniform, *profile);
    const auto finGained = convolveSurface(fin, finUniform, *profile, convex);
    double finMean = 0.0;
    int finCount = 0;
    for (std::size_t i = 0; i < fin.size(); ++i)
        if (fin.skin[i] && finPlain[i][0] > 0.0f) finMean += finGained[i][0] / finPlain[i][0] - 1.0, ++finCount;
    finMean /= std::max(finCount, 1);
    std::printf("convexity gain on builtin:ear's fin (L = 2 mm in red): mean %.5f over %d samples\n", finMean,
                finCount);
    // Against 0.05 on the sphere; 0.105 without the fade and the 20 mm bound (the rim's ~1 mm radius).
    EXPECT_LT(std::abs(finMean), 0.02);

    const Model plane = tessellateSkin(test_models::makeSquare(40.0f), 1.0f, 1.0f);
    const SurfaceSamples flat = gatherSurfaceSamples(plane, 1.0f);
    const auto onPlane = convolveSurface(flat, std::vector<glm::vec3>(flat.size(), glm::vec3(1.0f)), *profile, convex);
    for (std::size_t i = 0; i < flat.size(); ++i)
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(onPlane[i][c], flat.albedo[i][c], 1e-4) << i;
}

TEST(SurfaceConvolution, AConvexEdgeIsNoThinPart) {
    // Two half-planes meeting at a right angle (z = 0 for x ≤ 0, normal +z; x = 0 for z ≤ 0, normal +x), uniformly
    // lit: a body's edge, like builtin:head's neck meeting its cap. The sources round the corner turn by 90°; they
    // are no thin part's far side, so a through-light gain must not touch them: every receiver keeps E·α. (With the
    // far side bounded at 90°, n_p · n_q ≤ 0, they got the gain: receivers near the edge came out brighter.)
    SurfaceSamples s;
    const float h = 0.25f;
    std::vector<std::uint32_t> receivers;
    for (int j = -40; j <= 40; ++j)
        for (int i = 1; i <= 60; ++i) {
            if (j == 0) receivers.push_back(static_cast<std::uint32_t>(s.size()));
            s.positionMm.push_back(glm::vec3(-(i - 0.5f) * h, j * h, 0.0f)); // the top face
            s.normal.push_back(glm::vec3(0.0f, 0.0f, 1.0f));
            s.positionMm.push_back(glm::vec3(0.0f, j * h, -(i - 0.5f) * h)); // the side face
            s.normal.push_back(glm::vec3(1.0f, 0.0f, 0.0f));
            for (int k = 0; k < 2; ++k) {
                s.albedo.push_back(glm::vec3(1.0f));
                s.areaMm2.push_back(h * h);
                s.skin.push_back(1);
            }
        }
    ConvolutionSettings settings;
    settings.throughGain = {10.0, 10.0, 10.0};
    const auto out = convolveSurface(s, std::vector<glm::vec3>(s.size(), glm::vec3(1.0f)),
                                     *makeRadialProfile(profileParams("deon")), settings, &receivers);
    double worst = 0.0;
    for (const std::uint32_t i : receivers)
        for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(double(out[i][c]) - 1.0));
    std::printf("convex edge, through gain 10: worst |out − E·α| = %.6f over %zu receivers\n", worst, receivers.size());
    EXPECT_LT(worst, 1e-5);
}

TEST(SurfaceConvolution, DeterministicForAnyThreadCount) {
    const Model plane = tessellateSkin(test_models::makeSquare(20.0f), 0.8f, 1.0f);
    const SurfaceSamples samples = gatherSurfaceSamples(plane, 1.0f);
    const auto profile = makeRadialProfile(profileParams("burley"));
    const auto irradiance = stepIrradiance(samples, 0.1f);
    ConvolutionSettings one, three;
    one.threads = 1;
    three.threads = 3;
    EXPECT_EQ(convolveSurface(samples, irradiance, *profile, one),
              convolveSurface(samples, irradiance, *profile, three));
}

namespace {
// Two parallel square grids of skin samples (side 30 mm, spacing 0.5 mm, albedo 1): the first at z = 0 with
// normal +z, the second at z = zSecond with normal secondNormalZ · z. Returns the samples; `first` gets the index
// of the first grid's centre sample, `second` the second's.
SurfaceSamples twoPlanes(float zSecond, float secondNormalZ, std::uint32_t& first, std::uint32_t& second) {
    SurfaceSamples s;
    const int n = 61;
    const float h = 0.5f;
    for (int plane = 0; plane < 2; ++plane)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                if (i == n / 2 && j == n / 2) (plane == 0 ? first : second) = static_cast<std::uint32_t>(s.size());
                s.positionMm.push_back(glm::vec3((i - n / 2) * h, (j - n / 2) * h, plane == 0 ? 0.0f : zSecond));
                s.normal.push_back(glm::vec3(0.0f, 0.0f, plane == 0 ? 1.0f : secondNormalZ));
                s.albedo.push_back(glm::vec3(1.0f));
                s.areaMm2.push_back(h * h);
                s.skin.push_back(1);
            }
    return s;
}
} // namespace

TEST(SurfaceConvolution, ThroughTissueKeepsThinPartsBrightAndCarriesTheirThroughLight) {
    // A 2 mm slab: front face z = 0 (normal +z), back face z = −2 mm (normal −z).
    std::uint32_t front = 0, back = 0;
    const SurfaceSamples slab = twoPlanes(-2.0f, -1.0f, front, back);
    const auto profile = makeRadialProfile(profileParams("deon"));
    std::vector<glm::vec3> frontLit(slab.size()), backLit(slab.size());
    for (std::size_t i = 0; i < slab.size(); ++i) {
        frontLit[i] = glm::vec3(slab.normal[i].z > 0.0f ? 1.0f : 0.0f);
        backLit[i] = glm::vec3(1.0f) - frontLit[i];
    }
    ConvolutionSettings euclidean, tissue;
    euclidean.transport = Transport::Euclidean;
    const auto oldFront = convolveSurface(slab, frontLit, *profile, euclidean);
    const auto newFront = convolveSurface(slab, frontLit, *profile, tissue);
    const auto oldBack = convolveSurface(slab, backLit, *profile, euclidean);
    const auto newBack = convolveSurface(slab, backLit, *profile, tissue);
    for (int c = 0; c < 3; ++c) {
        // T: the kernel weight of the back face relative to the front's, from the Euclidean back-lit response
        // t = T / (1 + T).
        const double t = oldBack[front][c];
        const double transmission = t / (1.0 - t);
        // Euclidean: the front-lit front is dimmed to 1 / (1 + T); through tissue: it keeps E·α exactly.
        EXPECT_NEAR(oldFront[front][c], 1.0 / (1.0 + transmission), 1e-4) << c;
        EXPECT_NEAR(newFront[front][c], 1.0, 1e-5) << c;
        // Back-lit: the front receives T itself (not T / (1 + T)).
        EXPECT_NEAR(newBack[front][c], transmission, 1e-4) << c;
        EXPECT_GT(newBack[front][c], oldBack[front][c]) << c;
    }
    // Red, the widest lobe, carries the most light through 2 mm; the difference is large enough to matter.
    EXPECT_GT(newBack[front][0], 0.05);
    EXPECT_GT(newBack[front][0], newBack[front][2]);
    // The through-light gain scales exactly the light from the far side: back-lit, the front receives g·T;
    // front-lit, nothing changes (the far side is dark and the normaliser holds only the near side).
    ConvolutionSettings gained;
    gained.throughGain = {1.8, 3.0, 0.5};
    const auto gainedBack = convolveSurface(slab, backLit, *profile, gained);
    const auto gainedFront = convolveSurface(slab, frontLit, *profile, gained);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(gainedBack[front][c], gained.throughGain[c] * newBack[front][c], 1e-5) << c;
        EXPECT_NEAR(gainedFront[front][c], 1.0, 1e-5) << c;
    }
}

TEST(SurfaceConvolution, ThroughTissueStopsLightAcrossAnAirGap) {
    // Two surfaces facing each other across a 2 mm air gap (lips, an ear fold): the lower one (normal +z) lit, the
    // upper one (z = 2 mm, normal −z) dark. The Euclidean convolution moves light across; through tissue none.
    std::uint32_t lower = 0, upper = 0;
    const SurfaceSamples gap = twoPlanes(2.0f, -1.0f, lower, upper);
    const auto profile = makeRadialProfile(profileParams("deon"));
    std::vector<glm::vec3> irradiance(gap.size());
    for (std::size_t i = 0; i < gap.size(); ++i) irradiance[i] = glm::vec3(gap.normal[i].z > 0.0f ? 1.0f : 0.0f);
    ConvolutionSettings euclidean, tissue;
    euclidean.transport = Transport::Euclidean;
    const auto across = convolveSurface(gap, irradiance, *profile, euclidean);
    const auto stopped = convolveSurface(gap, irradiance, *profile, tissue);
    EXPECT_GT(across[upper][0], 0.05);
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(stopped[upper][c], 0.0f) << c;
        EXPECT_NEAR(stopped[lower][c], 1.0, 1e-5) << c;
        EXPECT_LT(across[lower][c], 1.0f) << c; // the dark upper face dilutes the lit one in the old normaliser
    }
}

TEST(SurfaceConvolution, ThroughGainGrowsWithTheSquaredDistanceThroughThePart) {
    // The 2 mm slab of the test above; one back sample lit at a time: the one straight behind the front's centre
    // (d = 2 mm) and one 3 mm to the side of it (d = √13 mm). The front centre's light from each grows by exactly
    // exp(k_c d²) against the constant gain; the near side's light and the normaliser do not change.
    std::uint32_t front = 0, back = 0;
    const SurfaceSamples slab = twoPlanes(-2.0f, -1.0f, front, back);
    const std::uint32_t aside = back + 6; // 6 columns of 0.5 mm: 3 mm along x
    ASSERT_FLOAT_EQ(slab.positionMm[aside].x - slab.positionMm[back].x, 3.0f);
    const auto profile = makeRadialProfile(profileParams("deon"));
    ConvolutionSettings constant, growing, redOnly;
    constant.throughGain = growing.throughGain = redOnly.throughGain = {1.7, 5.3, 9.4};
    growing.throughGrowthPerMm2 = {0.04, -0.05, -0.2};
    redOnly.throughGrowthPerMm2 = {0.04, 0.0, 0.0};
    for (const std::uint32_t lit : {back, aside}) {
        std::vector<glm::vec3> irradiance(slab.size(), glm::vec3(0.0f));
        irradiance[lit] = glm::vec3(1.0f);
        const auto flat = convolveSurface(slab, irradiance, *profile, constant);
        const auto grown = convolveSurface(slab, irradiance, *profile, growing);
        const auto red = convolveSurface(slab, irradiance, *profile, redOnly);
        const double d = glm::length(slab.positionMm[lit] - slab.positionMm[front]);
        for (int c = 0; c < 3; ++c) {
            ASSERT_GT(flat[front][c], 0.0f) << c;
            EXPECT_NEAR(grown[front][c] / flat[front][c], std::exp(growing.throughGrowthPerMm2[c] * d * d), 1e-5)
                << "d " << d << ", channel " << c;
        }
        EXPECT_GT(grown[front][0], flat[front][0]);
        // k = 0 reproduces the constant gain exactly (green and blue of the red-only growth), everywhere.
        for (std::size_t i = 0; i < slab.size(); ++i) {
            EXPECT_EQ(red[i][1], flat[i][1]) << i;
            EXPECT_EQ(red[i][2], flat[i][2]) << i;
        }
    }
    // Front-lit (its far side dark), the front does not change: the growth acts on the far side's light only and
    // never enters the normaliser.
    std::vector<glm::vec3> frontLit(slab.size());
    for (std::size_t i = 0; i < slab.size(); ++i) frontLit[i] = glm::vec3(slab.normal[i].z > 0.0f ? 1.0f : 0.0f);
    const auto frontGrowing = convolveSurface(slab, frontLit, *profile, growing);
    const auto frontConstant = convolveSurface(slab, frontLit, *profile, constant);
    for (std::size_t i = 0; i < slab.size(); ++i)
        if (slab.normal[i].z > 0.0f) {
            EXPECT_EQ(frontGrowing[i], frontConstant[i]) << i;
        }
    // The Euclidean transport has no far side: the gain and its growth do not apply.
    ConvolutionSettings euclidean = growing, euclideanFlat;
    euclidean.transport = euclideanFlat.transport = Transport::Euclidean;
    EXPECT_EQ(convolveSurface(slab, frontLit, *profile, euclidean),
              convolveSurface(slab, frontLit, *profile, euclideanFlat));
}
