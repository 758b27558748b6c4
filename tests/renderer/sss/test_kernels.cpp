// Discretised kernels: normalisation, symmetry, the artistic kernel against hand-computed taps, importance sampling,
// the gaussian-sum cascade, tabulated .bn kernels (docs/methods.md).
#include "reference_data.h"
#include "renderer/sss/artistic_kernel.h"
#include "renderer/sss/burley_profile.h"
#include "renderer/sss/discretisation.h"
#include "renderer/sss/gaussian_sum_profile.h"
#include "renderer/sss/kernel.h"
#include "renderer/sss/tabulated_kernel.h"
#include "tests/common/temp_folder.h"

#include "common/error.h"
#include "common/files.h"

#include <cmath>
#include <filesystem>
#include <gtest/gtest.h>
#include <numbers>
#include <unistd.h>

using namespace skinlab::renderer::sss;
namespace fs = std::filesystem;

namespace {
void expectNormalisedSymmetric(const std::vector<KernelTap>& taps, const std::string& what) {
    ASSERT_EQ(taps.size() % 2, 1u) << what;
    const size_t half = taps.size() / 2;
    EXPECT_EQ(taps[half].offsetMm, 0.0) << what;
    for (int c = 0; c < 3; ++c) {
        double sum = 0.0;
        for (const auto& tap : taps) {
            sum += tap.weight[c];
            EXPECT_GE(tap.weight[c], 0.0) << what;
        }
        // 1e-12: sums of ≤ 101 doubles that were divided by their own sum.
        EXPECT_NEAR(sum, 1.0, 1e-12) << what << " channel " << c;
    }
    for (size_t i = 0; i < half; ++i) {
        EXPECT_NEAR(taps[i].offsetMm, -taps[taps.size() - 1 - i].offsetMm, 1e-12) << what;
        EXPECT_LT(taps[i].offsetMm, taps[i + 1].offsetMm) << what;
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(taps[i].weight[c], taps[taps.size() - 1 - i].weight[c], 1e-9) << what;
    }
}

SssParams paramsFor(SssMethod method, int samples, TapPlacement placement, std::string profile = "deon",
                    std::string material = "skin") {
    SssParams p;
    p.method = method;
    p.samples = samples;
    p.placement = placement;
    p.profile = std::move(profile);
    p.material = std::move(material);
    return p;
}
} // namespace

// Data-driven sweep: every method, profile, placement and sample count gives normalised symmetric stages.
TEST(Kernels, EveryStageOfEveryMethodIsNormalisedAndSymmetric) {
    struct Case {
        SssMethod method;
        std::string profile;
        std::string material;
    };
    const std::vector<Case> cases{
        {methodId("separable"), "deon", "skin"},     {methodId("separable"), "burley", "skin"},
        {methodId("separable"), "burley", "marble"}, {methodId("separable"), "burley", "ketchup"},
        {methodId("artistic"), "deon", "skin"},      {methodId("gaussian-sum"), "deon", "skin"}};
    for (const auto& kase : cases)
        for (TapPlacement placement : {TapPlacement::Quadratic, TapPlacement::Importance})
            for (int samples : {3, 5, 7, 21, 25, 101}) {
                const Kernel kernel =
                    makeKernel(paramsFor(kase.method, samples, placement, kase.profile, kase.material));
                const std::string what = std::string(methodName(kase.method)) + "/" + kase.profile + "/" +
                                         kase.material + "/" + std::string(placementName(placement)) +
                                         "/N=" + std::to_string(samples);
                ASSERT_FALSE(kernel.stages.empty()) << what;
                double accumulated[3] = {0, 0, 0};
                for (const auto& stage : kernel.stages) {
                    EXPECT_EQ(stage.taps.size(), size_t(samples)) << what;
                    expectNormalisedSymmetric(stage.taps, what);
                    for (int c = 0; c < 3; ++c) accumulated[c] += stage.accumulate[c];
                }
                for (int c = 0; c < 3; ++c) EXPECT_NEAR(accumulated[c], 1.0, 1e-12) << what;
            }
    EXPECT_TRUE(makeKernel(SssParams{}).stages.empty()); // method none
}

TEST(Kernels, ArtisticBaselineMatchesHandComputedTapsForSevenSamples) {
    // N = 7 ≤ 20 ⇒ RANGE = 2; t = −2, −4/3, −2/3, 0, …; o = RANGE·sign(t)·t²/RANGE² = ±2, ±8/9, ±2/9, 0.
    // Trapezoid areas (|o_i − o_{i−1}| + |o_i − o_{i+1}|)/2: 5/9, 8/9, 4/9, 2/9, 4/9, 8/9, 5/9.
    const double offsets[7] = {-2.0, -8.0 / 9, -2.0 / 9, 0.0, 2.0 / 9, 8.0 / 9, 2.0};
    const double areas[7] = {5.0 / 9, 8.0 / 9, 4.0 / 9, 2.0 / 9, 4.0 / 9, 8.0 / 9, 5.0 / 9};
    const double strength[3] = {0.48, 0.41, 0.28};
    const double falloff[3] = {1.0, 0.37, 0.3};
    // The demo's profile: d'Eon red weights of lobes 2-6, G(v, r/(0.001 + falloff)).
    auto profile = [](double r, double f) {
        const double rr = r / (0.001 + f);
        auto g = [&](double v) { return std::exp(-rr * rr / (2 * v)) / (2 * std::numbers::pi * v); };
        return 0.100 * g(0.0484) + 0.118 * g(0.187) + 0.113 * g(0.567) + 0.358 * g(1.99) + 0.078 * g(7.41);
    };
    double expected[7][3];
    for (int c = 0; c < 3; ++c) {
        double sum = 0.0;
        for (int i = 0; i < 7; ++i) sum += expected[i][c] = areas[i] * profile(offsets[i], falloff[c]);
        for (int i = 0; i < 7; ++i) expected[i][c] /= sum;
        for (int i = 0; i < 7; ++i)
            expected[i][c] = i == 3 ? (1 - strength[c]) + strength[c] * expected[i][c] : strength[c] * expected[i][c];
    }
    const auto taps = artisticTaps(7, {0.48, 0.41, 0.28}, {1.0, 0.37, 0.3});
    ASSERT_EQ(taps.size(), 7u);
    for (int i = 0; i < 7; ++i) {
        EXPECT_NEAR(taps[i].offsetMm, offsets[i], 1e-12) << "tap " << i;
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(taps[i].weight[c], expected[i][c], 1e-12) << "tap " << i << " ch " << c;
    }
    // Per-channel centre weight (the thesis code mixed channels here): centre_c = 1 − s_c + s_c · w_c.
    EXPECT_GT(taps[3].weight[2], taps[3].weight[1]);
    EXPECT_GT(taps[3].weight[1], taps[3].weight[0]);
}

TEST(Kernels, ArtisticRangeIsThreeAboveTwentySamplesAndWidthScalesOffsets) {
    EXPECT_NEAR(artisticTaps(21, {1, 1, 1}, {1, 1, 1}).back().offsetMm, 3.0, 1e-12);
    EXPECT_NEAR(artisticTaps(19, {1, 1, 1}, {1, 1, 1}).back().offsetMm, 2.0, 1e-12);
    SssParams p = paramsFor(methodId("artistic"), 25, TapPlacement::Quadratic);
    p.widthMm = 6.0; // twice the profile scale
    EXPECT_NEAR(makeKernel(p).stages[0].taps.back().offsetMm, 6.0, 1e-12);
}

TEST(Kernels, ImportanceSamplingGivesTheWidestChannelEqualWeights) {
    GaussianSumProfile deon(deonSkinLobes(), "d'Eon");
    ASSERT_EQ(deon.widestChannel(), 0);
    const auto taps = importanceTaps(deon, 13);
    for (const auto& tap : taps) EXPECT_NEAR(tap.weight[0], 1.0 / 13, 1e-9);
    // Narrower channels put more weight on the centre tap.
    EXPECT_GT(taps[6].weight[2], taps[6].weight[0]);
}

TEST(Kernels, QuadraticTapsHandleBurleysSingularCentre) {
    BurleyProfile burley({0.4, 0.1, 0.06}, "test");
    const auto taps = quadraticTaps(burley, 21);
    for (const auto& tap : taps)
        for (double w : tap.weight) EXPECT_TRUE(std::isfinite(w));
    // Hand computation of the rule: raw weight a(o_i) · trapezoid area, except the centre whose raw weight is the
    // integral of the marginal over its cell [−o_1/2, o_1/2]; then each channel divided by its raw sum.
    for (int c = 0; c < 3; ++c) {
        std::vector<double> raw(taps.size());
        double sum = 0.0;
        for (size_t i = 0; i < taps.size(); ++i) {
            const double o = taps[i].offsetMm;
            const double left = i > 0 ? o - taps[i - 1].offsetMm : 0.0;
            const double right = i + 1 < taps.size() ? taps[i + 1].offsetMm - o : 0.0;
            raw[i] = i == 10 ? burley.cumulative(c, 0.5 * right) - burley.cumulative(c, -0.5 * left)
                             : burley.density(c, o) * 0.5 * (left + right);
            sum += raw[i];
        }
        for (size_t i = 0; i < taps.size(); ++i) EXPECT_NEAR(taps[i].weight[c], raw[i] / sum, 1e-12) << i;
        EXPECT_GT(taps[10].weight[c], 0.0);
    }
}

TEST(Kernels, GaussianSumStagesAddUpToDeonVariances) {
    SssParams p = paramsFor(methodId("gaussian-sum"), 21, TapPlacement::Quadratic);
    const Kernel kernel = makeKernel(p);
    ASSERT_EQ(kernel.stages.size(), 6u);
    double variance = 0.0;
    for (size_t i = 0; i < 6; ++i) {
        variance += kernel.stages[i].varianceMm2;
        EXPECT_NEAR(variance, deonSkinLobes()[i].varianceMm2, 1e-12);
        EXPECT_EQ(kernel.stages[i].accumulate, deonSkinLobes()[i].weight);
        // The discretised Gaussian keeps its variance within 5 % at 21 taps: truncating 0.2 % of the tail energy
        // (±3.09 σ) removes 2.1 % of a Gaussian's variance, the quadratic trapezoid rule another ~1.3 %.
        const auto stats = tapStatistics(kernel.stages[i].taps, 1e9);
        EXPECT_NEAR(stats.rmsWidthMm[0] * stats.rmsWidthMm[0] / kernel.stages[i].varianceMm2, 1.0, 0.05) << i;
    }
}

TEST(Kernels, SupportRadiusOfTheCascadeIsThatOfItsWidestGaussian) {
    // Quadratic taps reach the radius leaving 0.2 % of a Gaussian outside: 3.0902 σ. The cascade of incremental
    // stages reaches 3.0902 √7.41 mm (its total variance is d'Eon's widest lobe).
    const Kernel kernel = makeKernel(paramsFor(methodId("gaussian-sum"), 21, TapPlacement::Quadratic));
    EXPECT_NEAR(kernel.supportRadiusMm(), 3.0902 * std::sqrt(7.41), 1e-3);
    SssParams artistic = paramsFor(methodId("artistic"), 25, TapPlacement::Quadratic);
    EXPECT_DOUBLE_EQ(makeKernel(artistic).supportRadiusMm(), 3.0);
    EXPECT_EQ(makeKernel(SssParams{}).supportRadiusMm(), 0.0);
}

TEST(Kernels, SeparableDeonTapsKeepTheMarginalsWidth) {
    GaussianSumProfile deon(deonSkinLobes(), "d'Eon");
    for (TapPlacement placement : {TapPlacement::Quadratic, TapPlacement::Importance}) {
        const Kernel kernel = makeKernel(paramsFor(methodId("separable"), 101, placement));
        const auto stats = tapStatistics(kernel.stages[0].taps, 2.0);
        for (int c = 0; c < 3; ++c) {
            // 101 taps: RMS width within 5 % of the continuous marginal's, tail share beyond 2 mm within 0.02.
            EXPECT_NEAR(stats.rmsWidthMm[c] / std::sqrt(deon.secondMoment(c)), 1.0, 0.05)
                << placementName(placement) << " channel " << c;
            EXPECT_NEAR(stats.energyBeyond[c], deon.tailEnergy(c, 2.0), 0.02) << placementName(placement);
        }
    }
}

TEST(Kernels, InconsistentParametersAreInputErrors) {
    try {
        makeKernel(paramsFor(methodId("separable"), 21, TapPlacement::Quadratic, "deon", "marble"));
        FAIL() << "no exception";
    } catch (const skinlab::InputError& e) {
        EXPECT_STREQ(e.what(),
                     "sss.material: 'marble' has no d'Eon profile (only 'skin'); use sss.profile = \"burley\"");
    }
}

// --- tabulated kernels (.bn) ---

namespace {
std::string floats(std::initializer_list<float> values) {
    std::string bytes;
    for (float v : values) bytes.append(reinterpret_cast<const char*>(&v), 4);
    return bytes;
}
std::string errorOf(const fs::path& path) {
    try {
        readTabulatedKernel(path);
    } catch (const skinlab::InputError& e) {
        return e.what();
    }
    return "no error";
}
} // namespace

TEST(TabulatedKernel, ReadsAWellFormedFile) {
    const skinlab::test_support::TempFolder folder;
    const fs::path file = folder / "three.bn";
    skinlab::writeFileAtomic(file, floats({12, 0.25f, 0.2f, 0.1f, -1, 0.5f, 0.6f, 0.8f, 0, 0.25f, 0.2f, 0.1f, 1}));
    const auto rows = readTabulatedKernel(file);
    ASSERT_EQ(rows.size(), 3u);
    EXPECT_FLOAT_EQ(rows[1].weight[2], 0.8f);
    EXPECT_FLOAT_EQ(rows[2].offsetMm, 1.0f);
    TabulatedMarginal marginal(rows, "three");
    EXPECT_NEAR(marginal.cumulative(1, 0.0), 0.5, 1e-7);
    EXPECT_NEAR(marginal.cumulative(1, -1.5), 0.0, 1e-12);
    EXPECT_NEAR(marginal.cumulative(1, 1.5), 1.0, 1e-7);
    // Second moment of the piecewise-constant density: Σ w (x² + Δx²/12).
    EXPECT_NEAR(marginal.secondMoment(0), 0.5 * 1.0 + 1.0 / 12.0, 1e-7);
}

TEST(TabulatedKernel, BadFilesAreNamedInTheError) {
    const skinlab::test_support::TempFolder folder;
    const fs::path& dir = folder.path();
    EXPECT_EQ(errorOf(dir / "missing.bn"), (dir / "missing.bn").string() + ": kernel file not found");
    skinlab::writeFileAtomic(dir / "short.bn", floats({12, 0.25f, 0.2f, 0.1f, -1, 0.5f}));
    EXPECT_EQ(errorOf(dir / "short.bn"),
              (dir / "short.bn").string() + ": truncated: header says 12 floats, file holds 5");
    skinlab::writeFileAtomic(dir / "empty.bn", "");
    EXPECT_EQ(errorOf(dir / "empty.bn"), (dir / "empty.bn").string() + ": truncated: 0 bytes, no header");
    skinlab::writeFileAtomic(dir / "text.bn", "hello world, not a kernel\n");
    EXPECT_NE(errorOf(dir / "text.bn").find("text.bn: not a .bn kernel"), std::string::npos)
        << errorOf(dir / "text.bn");
    skinlab::writeFileAtomic(dir / "odd.bn", floats({6, 1, 1, 1, 0, 1, 1}));
    EXPECT_EQ(errorOf(dir / "odd.bn"),
              (dir / "odd.bn").string() + ": not a .bn kernel: 6 floats is not a multiple of 4");
    skinlab::writeFileAtomic(dir / "negative.bn",
                             floats({12, 0.25f, 0.2f, 0.1f, -1, -0.5f, 0.6f, 0.8f, 0, 0.25f, 0.2f, 0.1f, 1}));
    EXPECT_EQ(errorOf(dir / "negative.bn"),
              (dir / "negative.bn").string() + ": row 1: weight -0.500000 is not a finite non-negative number");
    skinlab::writeFileAtomic(dir / "uneven.bn",
                             floats({12, 0.25f, 0.2f, 0.1f, -1, 0.5f, 0.6f, 0.8f, 0, 0.25f, 0.2f, 0.1f, 3}));
    EXPECT_EQ(errorOf(dir / "uneven.bn"), (dir / "uneven.bn").string() + ": row 1: offsets are not uniformly spaced");
}

TEST(TabulatedKernel, PublishedSkin1KernelLoads) {
    const fs::path skin1 = skinlab::test::referenceKernel("Skin1");
    SKINLAB_REQUIRE_REFERENCE(skin1);
    const auto rows = readTabulatedKernel(skin1);
    ASSERT_EQ(rows.size(), 618u); // README: 618 rows, x in [−10.35, 10.35]
    EXPECT_NEAR(rows.front().offsetMm, -10.35, 0.01);
    EXPECT_NEAR(rows.back().offsetMm, 10.35, 0.01);
    for (int c = 0; c < 3; ++c) {
        double sum = 0.0;
        for (const auto& row : rows) sum += row.weight[c];
        EXPECT_NEAR(sum, 1.0, 1e-5);
    }
    // Discretised through the separable method with a file: profile.
    SssParams p;
    p.method = methodId("separable");
    p.profile = "file:" + skin1.string();
    for (TapPlacement placement : {TapPlacement::Quadratic, TapPlacement::Importance}) {
        p.placement = placement;
        expectNormalisedSymmetric(makeKernel(p).stages[0].taps, "skin1");
    }
}

TEST(TabulatedKernel, TruncatedCopyOfPublishedKernelIsRejected) {
    const fs::path skin2 = skinlab::test::referenceKernel("Skin2");
    SKINLAB_REQUIRE_REFERENCE(skin2);
    const std::string bytes = skinlab::readFile(skin2);
    const skinlab::test_support::TempFolder folder;
    const fs::path cut = folder / "Skin2_cut.bn";
    skinlab::writeFileAtomic(cut, std::string_view(bytes).substr(0, bytes.size() / 2));
    EXPECT_EQ(errorOf(cut), cut.string() + ": truncated: header says 2248 floats, file holds 1123");
}
