// The scene spec's [skin] table (renderer/scene/skin_spec.h): levels and values, what every method then reads (the
// kernels, the object-space reference's radial profile, the transmittance weights, the Blender radii), and the
// one-line errors naming the key.
#include "common/error.h"
#include "renderer/pathtraced/blender_scene.h"
#include "renderer/scene/scene_spec.h"
#include "renderer/sss/kernel.h"
#include "renderer/sss/radial_profile.h"
#include "renderer/sss/skin_model.h"

#include <gtest/gtest.h>

namespace skinlab::renderer {
namespace {

std::string errorOf(const std::vector<std::string>& overrides) {
    try {
        loadSceneSpec("builtin:head", overrides, {});
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

double kernelSecondMoment(const sss::Kernel& kernel, int channel) {
    double moment = 0.0;
    for (const auto& stage : kernel.stages)
        for (const auto& tap : stage.taps)
            moment += tap.weight[static_cast<std::size_t>(channel)] * tap.offsetMm * tap.offsetMm;
    return moment;
}

TEST(SkinSpec, AbsentTableLeavesTheSceneAsItWas) {
    const SceneSpec spec = loadSceneSpec("builtin:head", {}, {});
    EXPECT_FALSE(spec.skin.has_value());
    EXPECT_FALSE(spec.sss.skinLobeWeights.has_value());
    EXPECT_FALSE(spec.resolved.contains("skin"));
    const auto lobes = sss::skinProfileLobes(spec.sss);
    for (std::size_t k = 0; k < lobes.size(); ++k) EXPECT_EQ(lobes[k].weight, sss::deonSkinLobes()[k].weight);
    EXPECT_EQ(sss::skinWidthRatio(spec.sss), (std::array<double, 3>{1.0, 1.0, 1.0}));
}

TEST(SkinSpec, NamedLevelSetsTheToneAndIsRecorded) {
    const SceneSpec spec = loadSceneSpec("builtin:head", {"skin.tone=\"V\""}, {});
    ASSERT_TRUE(spec.skin.has_value());
    EXPECT_DOUBLE_EQ(spec.skin->tone.melanin, sss::skinToneForLevel("V")->melanin);
    EXPECT_EQ(spec.resolved["skin"]["tone"], "V");
    EXPECT_DOUBLE_EQ(spec.resolved["skin"]["melanin"].get<double>(), spec.skin->tone.melanin);
    EXPECT_EQ(spec.resolved["skin"]["lobes"].size(), 6u);
    ASSERT_TRUE(spec.sss.skinLobeWeights.has_value());
    // A value instead of a level, haemoglobin and blend given.
    const SceneSpec byValue =
        loadSceneSpec("builtin:head", {"skin.melanin=0.3", "skin.haemoglobin=0.05", "skin.melanin_blend=0.5"}, {});
    EXPECT_DOUBLE_EQ(byValue.skin->tone.melanin, 0.3);
    EXPECT_DOUBLE_EQ(byValue.skin->tone.haemoglobin, 0.05);
    EXPECT_DOUBLE_EQ(byValue.skin->tone.melaninBlend, 0.5);
    EXPECT_EQ(byValue.resolved["skin"]["tone"], "");
}

TEST(SkinSpec, EveryMethodReadsTheTonesProfile) {
    const auto load = [](const std::string& tone, const std::string& method, const std::string& profile) {
        std::vector<std::string> overrides{"sss.method=\"" + method + "\""};
        if (!profile.empty()) overrides.push_back("sss.profile=\"" + profile + "\"");
        if (!tone.empty()) overrides.push_back("skin.tone=\"" + tone + "\"");
        return loadSceneSpec("builtin:head", overrides, {});
    };
    // Darker skin, narrower kernels: gaussian-sum and separable (d'Eon's variances, the tone's weights; Burley),
    // artistic (falloff widened per channel) and pscbf (its Gaussian widened per channel).
    for (const auto& [method, profile] : std::vector<std::pair<std::string, std::string>>{
             {"gaussian-sum", ""}, {"separable", "deon"}, {"separable", "burley"}, {"artistic", ""}, {"pscbf", ""}}) {
        const sss::Kernel light = sss::makeKernel(load("I", method, profile).sss);
        const sss::Kernel dark = sss::makeKernel(load("VI", method, profile).sss);
        for (int c = 0; c < 3; ++c) {
            if (method == "gaussian-sum") continue; // its taps are the fixed variances; the weights carry the tone
            EXPECT_LT(kernelSecondMoment(dark, c), kernelSecondMoment(light, c)) << method << profile << c;
        }
        EXPECT_NE(light.toJson().dump(), dark.toJson().dump()) << method << profile;
    }
    // The object-space reference: the radial profile's cutoff shrinks with melanin.
    for (const std::string profile : {"deon", "burley"}) {
        const auto light = sss::makeRadialProfile(load("I", "reference", profile).sss);
        const auto dark = sss::makeRadialProfile(load("VI", "reference", profile).sss);
        EXPECT_LT(dark->cutoffRadiusMm(1e-3), light->cutoffRadiusMm(1e-3)) << profile;
    }
    // Transmittance: T(0) = 1 with the tone's weights, and less light through 1 mm for darker skin's narrower profile.
    const SceneSpec light = load("I", "none", "");
    const SceneSpec dark = load("VI", "none", "");
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(sss::skinTransmittance(dark.sss, 0.0)[static_cast<std::size_t>(c)], 1.0, 1e-12);
        EXPECT_LE(sss::skinTransmittance(dark.sss, 1.0)[static_cast<std::size_t>(c)],
                  sss::skinTransmittance(light.sss, 1.0)[static_cast<std::size_t>(c)] + 1e-12);
    }
    // Cycles and EEVEE: the radii scale by the tone's width over d'Eon's, below 1 for the darkest level.
    for (double ratio : sss::skinWidthRatio(dark.sss)) EXPECT_LT(ratio, 1.0);
}

TEST(SkinSpec, BadValuesNameTheirKey) {
    EXPECT_EQ(errorOf({"skin.melanin=0.7"}), "builtin:head: skin.melanin: 0.7 is out of range [0.001, 0.5]");
    EXPECT_EQ(errorOf({"skin.melanin=0.1", "skin.haemoglobin=0.5"}),
              "builtin:head: skin.haemoglobin: 0.5 is out of range [0.001, 0.1]");
    EXPECT_EQ(errorOf({"skin.tone=\"VII\""}).rfind("builtin:head: skin.tone: ", 0), 0u)
        << errorOf({"skin.tone=\"VII\""});
    EXPECT_EQ(errorOf({"skin.tone=\"II\"", "skin.melanin=0.1"}),
              "builtin:head: skin.melanin: give skin.tone or skin.melanin, not both");
    EXPECT_EQ(errorOf({"skin.haemoglobin=0.05"}),
              "builtin:head: skin.melanin: missing ([skin] needs tone = \"I\" … \"VI\" or melanin)");
    EXPECT_EQ(errorOf({"skin.tone=\"II\"", "skin.melanin_blend=2"}),
              "builtin:head: skin.melanin_blend: 2 is out of range [0, 1]");
    EXPECT_EQ(errorOf({"skin.tone=\"II\"", "skin.oiliness=0.2"}), "builtin:head: skin.oiliness: unknown key");
}

} // namespace
} // namespace skinlab::renderer
