// Mikkelsen's pscbf taps (renderer/sss/pscbf_kernel.h): published parameters, tap placement at equal steps of the
// red CDF, re-weighting of green and blue, energy conservation through the CPU passes.
#include "renderer/sss/cpu_blur.h"
#include "renderer/sss/pscbf_kernel.h"

#include "common/error.h"
#include "common/spec.h"
#include "renderer/sss/kernel.h"
#include "renderer/sss/methods/pscbf.h"
#include "renderer/sss/sss_params.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

using namespace skinlab::renderer::sss;

TEST(PscbfKernel, PublishedSkinParameters) {
    const PscbfProfile& p = mikkelsenSkinProfile();
    EXPECT_DOUBLE_EQ(p.spike[0], 0.15);
    EXPECT_DOUBLE_EQ(p.spike[1], 0.18);
    EXPECT_DOUBLE_EQ(p.spike[2], 0.20);
    EXPECT_DOUBLE_EQ(p.varianceMm2[0], 2.3);
    EXPECT_DOUBLE_EQ(p.varianceMm2[1], 1.4);
    EXPECT_DOUBLE_EQ(p.varianceMm2[2], 1.1);
    EXPECT_DOUBLE_EQ(p.maxRadiusMm, 4.5);
    // r_max is 3 standard deviations of the red Gaussian (the reading of "variance" as v in mm²): 3·√2.3 = 4.55 mm,
    // published rounded to 4.5 mm (1.1 %).
    EXPECT_NEAR(3.0 * std::sqrt(p.varianceMm2[0]), p.maxRadiusMm, 0.02 * p.maxRadiusMm);
}

TEST(PscbfKernel, ThirteenSymmetricTapsInsideTheDisc) {
    const PscbfKernel kernel = makePscbfKernel();
    ASSERT_EQ(kernel.taps.size(), 13u);
    EXPECT_EQ(kernel.taps[6].offsetMm, 0.0);
    for (int k = 0; k < 13; ++k) {
        EXPECT_DOUBLE_EQ(kernel.taps[k].offsetMm, -kernel.taps[12 - k].offsetMm) << k;
        EXPECT_LT(std::abs(kernel.taps[k].offsetMm), 4.5) << k;
        if (k > 0) {
            EXPECT_GT(kernel.taps[k].offsetMm, kernel.taps[k - 1].offsetMm) << k;
        }
        for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(kernel.taps[k].weight[c], kernel.taps[12 - k].weight[c]);
    }
    for (int c = 0; c < 3; ++c) {
        double sum = 0.0;
        for (const auto& tap : kernel.taps) sum += tap.weight[c];
        EXPECT_NEAR(sum, 1.0, 1e-12) << "channel " << c;
    }
}

TEST(PscbfKernel, RedTapsSitAtEqualStepsOfTheRedCdf) {
    const PscbfKernel kernel = makePscbfKernel();
    for (int k = 0; k < 13; ++k) {
        // Every red tap carries probability 1/N and sits at the median of its cell, Q((k + ½)/N).
        EXPECT_NEAR(kernel.taps[k].weight[0], 1.0 / 13.0, 1e-12) << k;
        EXPECT_NEAR(pscbfTruncatedCumulative(kernel.profile, 0, kernel.taps[k].offsetMm), (k + 0.5) / 13.0, 1e-9) << k;
    }
}

TEST(PscbfKernel, GreenAndBlueAreReweightedNarrower) {
    const PscbfKernel kernel = makePscbfKernel();
    std::array<double, 3> meanSquare{};
    for (const auto& tap : kernel.taps)
        for (int c = 0; c < 3; ++c) meanSquare[c] += tap.weight[c] * tap.offsetMm * tap.offsetMm;
    // Narrower Gaussians (1.4, 1.1 < 2.3 mm²) put more weight on the central taps on the same positions.
    EXPECT_GT(meanSquare[0], meanSquare[1]);
    EXPECT_GT(meanSquare[1], meanSquare[2]);
    EXPECT_GT(kernel.taps[6].weight[2], kernel.taps[6].weight[1]);
    EXPECT_GT(kernel.taps[6].weight[1], kernel.taps[6].weight[0]);
    // Each channel's discrete variance approximates its Gaussian's variance truncated at ±r_max. For red, the cell
    // medians sit inside their own cells, so the discrete variance is lower; green and blue are narrower than the
    // red cells, whose medians lie outside their own conditional means, so theirs can be higher. 13 cells keep the
    // difference below 15 %.
    for (int c = 0; c < 3; ++c) {
        const double v = kernel.profile.varianceMm2[c];
        const double a = kernel.profile.maxRadiusMm / std::sqrt(v);
        const double phi = std::exp(-0.5 * a * a) / std::sqrt(2.0 * M_PI);
        const double truncated = v * (1.0 - 2.0 * a * phi / std::erf(a / std::sqrt(2.0)));
        if (c == 0) {
            EXPECT_LT(meanSquare[c], truncated);
        }
        EXPECT_NEAR(meanSquare[c] / truncated, 1.0, 0.15) << c;
    }
}

TEST(PscbfKernel, TwoPassesWithTheSpikeKeepEnergyAndFlatFields) {
    const PscbfKernel pscbf = makePscbfKernel();
    Kernel kernel;
    KernelStage spike;
    spike.taps = {KernelTap{0.0, {1.0, 1.0, 1.0}}};
    spike.accumulate = pscbf.profile.spike;
    kernel.stages = {spike, pscbf.broadStage()};
    for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(kernel.stages[0].accumulate[c] + kernel.stages[1].accumulate[c], 1.0);

    SurfaceBuffers surface;
    surface.width = surface.height = 41;
    surface.depth.assign(41 * 41, 100.0f);
    surface.mask.assign(41 * 41, 1.0f);
    surface.focalLengthPixels = 100.0f; // 1 mm = 1 pixel at depth 100 mm
    surface.mmPerUnit = 1.0f;
    std::vector<Rgb> flat(41 * 41, Rgb{0.3f, 0.5f, 0.7f});
    const auto flatOut = applyKernel(surface, flat, kernel, {});
    for (const auto& pixel : flatOut)
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(pixel[c], flat[0][c], 1e-5f);

    std::vector<Rgb> impulse(41 * 41, Rgb{0.0f, 0.0f, 0.0f});
    impulse[20 * 41 + 20] = Rgb{1.0f, 1.0f, 1.0f};
    const auto out = applyKernel(surface, impulse, kernel, {});
    for (int c = 0; c < 3; ++c) {
        double sum = 0.0;
        for (const auto& pixel : out) sum += pixel[c];
        EXPECT_NEAR(sum, 1.0, 1e-4) << c; // the footprint (±4.5 px) stays inside the 41 px image
        // The centre keeps at least the spike.
        EXPECT_GT(out[20 * 41 + 20][c], pscbf.profile.spike[c]);
    }
}

TEST(PscbfKernel, JsonRecordsTheParameters) {
    const auto json = makePscbfKernel().toJson();
    EXPECT_EQ(json.at("method"), "pscbf");
    EXPECT_EQ(json.at("taps").size(), 13u);
    EXPECT_DOUBLE_EQ(json.at("max_radius_mm").get<double>(), 4.5);
}

// The paper runs 13 taps per axis: an [sss] table that selects pscbf and names no count gets 13, the other methods
// keep 21, and an explicit count wins.
TEST(PscbfKernel, ThirteenTapsByDefaultFromTheSceneTable) {
    auto read = [](std::string_view text) {
        const toml::table root = skinlab::parseTomlString(text, "scene.toml");
        return readSssParams(skinlab::SpecReader(root, "scene.toml"));
    };
    EXPECT_EQ(read("[sss]\nmethod = \"pscbf\"\n").samples, 13);
    EXPECT_EQ(read("[sss]\nmethod = \"separable\"\n").samples, 21);
    EXPECT_EQ(read("[sss]\nmethod = \"pscbf\"\nsamples = 21\n").samples, 21);
    SssParams pscbf = read("[sss]\nmethod = \"pscbf\"\n");
    EXPECT_EQ(makeKernel(pscbf).stages.at(0).taps.size(), 13u);
    EXPECT_EQ(sssParamsFromJson(pscbf.toJson()).samples, 13);
}

// Table 1's 2.3 / 1.4 / 1.1 read as standard deviations (mm): variances 5.29 / 1.96 / 1.21 mm², the same spike and
// r_max. Under that reading r_max cuts the red Gaussian at 4.5 / 2.3 = 1.96 σ, so the red taps spread wider (RMS
// width closer to r_max). The reading is a key of [sss] and travels through the JSON form.
TEST(PscbfKernel, StandardDeviationReading) {
    const PscbfProfile& sd = mikkelsenSkinProfile(PscbfSigma::StdDev);
    EXPECT_DOUBLE_EQ(sd.varianceMm2[0], 2.3 * 2.3);
    EXPECT_DOUBLE_EQ(sd.varianceMm2[1], 1.4 * 1.4);
    EXPECT_DOUBLE_EQ(sd.varianceMm2[2], 1.1 * 1.1);
    EXPECT_EQ(sd.spike, mikkelsenSkinProfile().spike);
    EXPECT_DOUBLE_EQ(sd.maxRadiusMm, 4.5);

    const toml::table root =
        skinlab::parseTomlString("[sss]\nmethod = \"pscbf\"\npscbf_sigma = \"std-dev\"\n", "s.toml");
    const SssParams params = readSssParams(skinlab::SpecReader(root, "s.toml"));
    EXPECT_EQ(pscbfParams(params).sigma, PscbfSigma::StdDev);
    EXPECT_EQ(pscbfParams(sssParamsFromJson(params.toJson())).sigma, PscbfSigma::StdDev);
    SssParams variance = params;
    sssKey("pscbf_sigma").set(variance, PscbfSigma::Variance);
    EXPECT_EQ(pscbfParams(variance).sigma, PscbfSigma::Variance);
    const double wide = tapStatistics(makeKernel(params).stages.at(0).taps, 10.0).rmsWidthMm[0];
    const double narrow = tapStatistics(makeKernel(variance).stages.at(0).taps, 10.0).rmsWidthMm[0];
    // Truncated to ±4.5 mm the variance reading keeps an RMS near √2.3 = 1.52 mm; the other near 2.0 mm.
    EXPECT_NEAR(narrow, std::sqrt(2.3), 0.1);
    EXPECT_GT(wide, narrow + 0.3);
    EXPECT_LT(wide, 2.3);

    const toml::table bad = skinlab::parseTomlString("[sss]\npscbf_sigma = \"sigma\"\n", "s.toml");
    EXPECT_THROW(readSssParams(skinlab::SpecReader(bad, "s.toml")), skinlab::InputError);
}

// Bugs are caught in the builds that run: the kernel's preconditions are checked in the release preset too (they
// were `assert`s, compiled out there), and the message names the expression and both values.
TEST(PscbfKernelDeathTest, PreconditionsAreCheckedInEveryBuild) {
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    EXPECT_DEATH(makePscbfKernel(mikkelsenSkinProfile(), 4),
                 R"(check failed at .*pscbf_kernel\.cpp:[0-9]+: samples % 2 == 1 \(0 vs 1\))");
    EXPECT_DEATH(makePscbfKernel(mikkelsenSkinProfile(), 103), R"(samples <= 101 \(103 vs 101\))");
}
