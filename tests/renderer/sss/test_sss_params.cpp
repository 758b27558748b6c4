// The [sss] and [transmittance] spec tables: defaults, word-for-word errors, JSON round trip.
#include "renderer/sss/sss_params.h"

#include "common/error.h"
#include "common/spec.h"

#include <gtest/gtest.h>

using namespace skinlab::renderer::sss;

namespace {
SssParams readSss(std::string_view text) {
    const toml::table root = skinlab::parseTomlString(text, "scene.toml");
    return readSssParams(skinlab::SpecReader(root, "scene.toml"));
}
std::string sssError(std::string_view text) {
    try {
        readSss(text);
    } catch (const skinlab::InputError& e) {
        return e.what();
    }
    return "no error";
}
} // namespace

TEST(SssParams, DefaultsWhenTheTableIsAbsent) {
    const SssParams p = readSss("");
    EXPECT_EQ(p.method, SssMethod::None);
    EXPECT_EQ(p.samples, 21);
    EXPECT_DOUBLE_EQ(p.widthMm, 3.0);
    EXPECT_EQ(p.placement, TapPlacement::Quadratic);
    EXPECT_TRUE(p.followSurface);
    EXPECT_EQ(p.profile, "deon");
    EXPECT_EQ(p.material, "skin");
    EXPECT_EQ(p.artisticStrength, (std::array<double, 3>{0.48, 0.41, 0.28}));
    EXPECT_EQ(p.artisticFalloff, (std::array<double, 3>{1.0, 0.37, 0.3}));
}

TEST(SssParams, ReadsEveryKey) {
    const SssParams p = readSss(R"([sss]
method = "separable"
samples = 31
width_mm = 4.5
sampling = "importance"
follow_surface = false
follow_surface_k = 2.0
profile = "burley"
material = "marble"
artistic_strength = [0.1, 0.2, 0.3]
artistic_falloff = [0.4, 0.5, 0.6]
)");
    EXPECT_EQ(p.method, SssMethod::Separable);
    EXPECT_EQ(p.samples, 31);
    EXPECT_DOUBLE_EQ(p.widthMm, 4.5);
    EXPECT_EQ(p.placement, TapPlacement::Importance);
    EXPECT_FALSE(p.followSurface);
    EXPECT_DOUBLE_EQ(p.followSurfaceK, 2.0);
    EXPECT_EQ(p.profile, "burley");
    EXPECT_EQ(p.material, "marble");
    EXPECT_EQ(p.artisticFalloff[2], 0.6);
}

TEST(SssParams, ErrorsNameFileKeyAndValue) {
    EXPECT_EQ(sssError("[sss]\nmethod = \"blur\""),
              "scene.toml: sss.method: 'blur' is not one of: none, gaussian-sum, separable, artistic, pscbf, reference, pathtraced");
    EXPECT_EQ(sssError("[sss]\nsamples = 20"),
              "scene.toml: sss.samples: 20 is even; a symmetric kernel needs an odd number of taps (3…101)");
    EXPECT_EQ(sssError("[sss]\nsamples = 103"), "scene.toml: sss.samples: 103 is out of range [3, 101]");
    EXPECT_EQ(sssError("[sss]\nwidth_mm = 0"), "scene.toml: sss.width_mm: 0 is out of range [0.01, 100]");
    EXPECT_EQ(sssError("[sss]\nmaterial = \"marble\""),
              "scene.toml: sss.material: 'marble' has no d'Eon profile (only 'skin'); use sss.profile = \"burley\"");
    EXPECT_EQ(sssError("[sss]\nprofile = \"gauss\""),
              "scene.toml: sss.profile: 'gauss' is not one of: deon, burley, file:PATH");
    EXPECT_EQ(sssError("[sss]\nprofile = \"file:/nonexistent/Skin1.bn\""),
              "scene.toml: sss.profile: /nonexistent/Skin1.bn: kernel file not found");
    EXPECT_EQ(sssError("[sss]\nwidht_mm = 3"), "scene.toml: sss.widht_mm: unknown key");
    EXPECT_EQ(sssError("[sss]\nartistic_strength = [0.5, 0.5, 2]"),
              "scene.toml: sss.artistic_strength: element 2: 2 is out of range [0, 1]");
}

TEST(SssParams, JsonRoundTripAndValidation) {
    SssParams p;
    p.method = SssMethod::GaussianSum;
    p.samples = 11;
    p.widthMm = 2.5;
    p.profile = "burley";
    p.material = "apple";
    const SssParams back = sssParamsFromJson(p.toJson());
    EXPECT_EQ(back.toJson(), p.toJson());
    try {
        sssParamsFromJson({{"method", "separable"}, {"samples", 4}}, "stage settings");
        FAIL() << "no exception";
    } catch (const skinlab::InputError& e) {
        EXPECT_STREQ(e.what(),
                     "stage settings: sss.samples: 4 is even; a symmetric kernel needs an odd number of taps (3…101)");
    }
}

TEST(TransmittanceParams, ReadsAndValidates) {
    const toml::table root =
        skinlab::parseTomlString("[transmittance]\nenabled = true\ntranslucency = 0.83\n", "scene.toml");
    const TransmittanceParams t = readTransmittanceParams(skinlab::SpecReader(root, "scene.toml"));
    EXPECT_TRUE(t.enabled);
    EXPECT_DOUBLE_EQ(t.translucency, 0.83);
    EXPECT_EQ(transmittanceParamsFromJson(t.toJson()).toJson(), t.toJson());
    const toml::table bad = skinlab::parseTomlString("[transmittance]\ntranslucency = 1.5\n", "scene.toml");
    try {
        readTransmittanceParams(skinlab::SpecReader(bad, "scene.toml"));
        FAIL() << "no exception";
    } catch (const skinlab::InputError& e) {
        EXPECT_STREQ(e.what(), "scene.toml: transmittance.translucency: 1.5 is out of range [0, 1]");
    }
}
