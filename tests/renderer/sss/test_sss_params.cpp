// The [sss] and [transmittance] spec tables: defaults, word-for-word errors, JSON round trip.
#include "renderer/sss/sss_params.h"

#include "common/error.h"
#include "common/spec.h"
#include "renderer/sss/kernel.h"
#include "renderer/sss/methods/artistic.h"
#include "renderer/sss/methods/reference.h"
#include "renderer/sss/width_conventions.h"
#include "width_views.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

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
    EXPECT_EQ(p.method, methodId("none"));
    EXPECT_EQ(p.samples, 21);
    EXPECT_DOUBLE_EQ(p.widthMm, 3.0);
    EXPECT_EQ(p.placement, TapPlacement::Quadratic);
    EXPECT_TRUE(p.followSurface);
    EXPECT_EQ(p.profile, "deon");
    EXPECT_EQ(p.material, "skin");
    EXPECT_EQ(artisticParams(p).strength, (std::array<double, 3>{0.48, 0.41, 0.28}));
    EXPECT_EQ(artisticParams(p).falloff, (std::array<double, 3>{1.0, 0.37, 0.3}));
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
)");
    EXPECT_EQ(p.method, methodId("separable"));
    EXPECT_EQ(p.samples, 31);
    EXPECT_DOUBLE_EQ(p.widthMm, 4.5);
    EXPECT_EQ(p.placement, TapPlacement::Importance);
    EXPECT_FALSE(p.followSurface);
    EXPECT_DOUBLE_EQ(p.followSurfaceK, 2.0);
    EXPECT_EQ(p.profile, "burley");
    EXPECT_EQ(p.material, "marble");
    const SssParams artistic = readSss("[sss]\nmethod = \"artistic\"\nartistic_strength = [0.1, 0.2, 0.3]\n"
                                       "artistic_falloff = [0.4, 0.5, 0.6]\n");
    EXPECT_EQ(artisticParams(artistic).strength[0], 0.1);
    EXPECT_EQ(artisticParams(artistic).falloff[2], 0.6);
}

TEST(SssParams, ErrorsNameFileKeyAndValue) {
    EXPECT_EQ(sssError("[sss]\nmethod = \"blur\""), "scene.toml: sss.method: 'blur' is not one of: none, gaussian-sum, "
                                                    "separable, artistic, pscbf, reference, pathtraced, eevee");
    EXPECT_EQ(sssError("[sss]\nmethod = \"separable\"\nsamples = 20"),
              "scene.toml: sss.samples: 20 is even; a symmetric kernel needs an odd number of taps (3…101)");
    EXPECT_EQ(sssError("[sss]\nmethod = \"separable\"\nsamples = 103"),
              "scene.toml: sss.samples: 103 is out of range [3, 101]");
    EXPECT_EQ(sssError("[sss]\nwidth_mm = 0"), "scene.toml: sss.width_mm: 0 is out of range [0.01, 100]");
    EXPECT_EQ(sssError("[sss]\nmethod = \"separable\"\nmaterial = \"marble\""),
              "scene.toml: sss.material: 'marble' has no d'Eon profile (only 'skin'); use sss.profile = \"burley\"");
    EXPECT_EQ(sssError("[sss]\nmethod = \"separable\"\nprofile = \"gauss\""),
              "scene.toml: sss.profile: 'gauss' is not one of: deon, burley, file:PATH");
    EXPECT_EQ(sssError("[sss]\nmethod = \"separable\"\nprofile = \"file:/nonexistent/Skin1.bn\""),
              "scene.toml: sss.profile: /nonexistent/Skin1.bn: kernel file not found");
    EXPECT_EQ(sssError("[sss]\nwidht_mm = 3"), "scene.toml: sss.widht_mm: unknown key (did you mean width_mm?)");
    EXPECT_EQ(sssError("[sss]\nmethod = \"artistic\"\nartistic_strength = [0.5, 0.5, 2]"),
              "scene.toml: sss.artistic_strength: element 2: 2 is out of range [0, 1]");
}

TEST(SssParams, JsonRoundTripAndValidation) {
    SssParams p;
    p.method = methodId("gaussian-sum");
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

// Jimenez's demo (SSSSBlurPS): finalStep = sssWidth · (1 / tan(fovY/2)) / z · dir / 3 in texture coordinates per
// kernel unit, offsets of its artistic kernel in [−3, 3] (RANGE = 3 for more than 20 taps). Replays that step for a
// few views and compares where the outermost tap lands, in pixels, with skinlab's artistic kernel at the converted
// width (pixels per mm = f_px / (mm_per_unit · z), f_px = (H/2) / tan(fovY/2)). The old reading width_mm = sssWidth ×
// mm_per_unit lands at half the demo's distance.
TEST(SssParams, DemoSssWidthConversion) {
    for (const test::View& v : test::kViews) {
        const double demoStepUv = v.sssWidth * (1.0 / v.tanHalfFov()) / v.z / 3.0; // per kernel unit
        const double demoEdgePixels = 3.0 * demoStepUv * v.height;                 // vertical pass, offset 3
        const double edgePixels = test::artisticEdgePixels(widthMmFromDemoSssWidth(v.sssWidth, v.mmPerUnit), v);
        EXPECT_NEAR(edgePixels, demoEdgePixels, 1e-9 * demoEdgePixels) << "sssWidth " << v.sssWidth;
    }
    EXPECT_DOUBLE_EQ(widthMmFromDemoSssWidth(0.012, 47.9), 2.0 * 0.012 * 47.9);
}

// The demo's transmittance scale (SSSSTransmittance): s = 8.25 (1 − translucency) / sssWidth × thickness in world
// units. At the converted width, skinlab's per-unit scale is the same number; independent of mm_per_unit in mm.
TEST(TransmittanceParams, ThicknessScaleFollowsTheDemo) {
    for (const double translucency : {0.0, 0.5, 0.83}) {
        for (const double sssWidth : {0.012, 1.5}) {
            for (const double mmPerUnit : {1.0, 47.9}) {
                const double widthMm = widthMmFromDemoSssWidth(sssWidth, mmPerUnit);
                const double demo = 8.25 * (1.0 - translucency) / sssWidth;
                EXPECT_NEAR(transmittanceScalePerUnit(translucency, widthMm, mmPerUnit), demo, 1e-9 * (1.0 + demo));
            }
        }
    }
    // Per mm of thickness at width_mm = 3: 16.5 (1 − 0.5) / 3 = 2.75 / mm.
    EXPECT_NEAR(transmittanceScalePerUnit(0.5, 3.0, 1.0), 2.75, 1e-12);
}

// The keys of the thesis' variants: extension input, curvature measure and reference radius, transmittance form.
TEST(SssParams, ThesisVariantKeys) {
    const SssParams defaults = readSss("");
    EXPECT_EQ(defaults.extensionInput, "albedo");
    EXPECT_EQ(defaults.curvatureMeasure, "normal");
    EXPECT_DOUBLE_EQ(defaults.curvatureReferenceMm, 20.0);
    const SssParams p =
        readSss("[sss]\nmethod = \"separable\"\nextension_input = \"lit\"\ncurvature_measure = \"screen\"\n"
                "curvature_reference_mm = 40.0\n");
    EXPECT_EQ(p.extensionInput, "lit");
    EXPECT_EQ(p.curvatureMeasure, "screen");
    EXPECT_DOUBLE_EQ(p.curvatureReferenceMm, 40.0);
    EXPECT_EQ(sssParamsFromJson(p.toJson()).toJson(), p.toJson());
    EXPECT_EQ(sssError("[sss]\nmethod = \"separable\"\nextension_input = \"image\""),
              "scene.toml: sss.extension_input: 'image' is not one of: albedo, lit");
    EXPECT_EQ(sssError("[sss]\ncurvature_measure = \"gauss\""),
              "scene.toml: sss.curvature_measure: 'gauss' is not one of: normal, screen");

    const toml::table root = skinlab::parseTomlString("[transmittance]\ncurvature_form = \"thesis\"\n", "scene.toml");
    EXPECT_EQ(readTransmittanceParams(skinlab::SpecReader(root, "scene.toml")).curvatureForm, "thesis");
    const toml::table bad = skinlab::parseTomlString("[transmittance]\ncurvature_form = \"both\"\n", "scene.toml");
    EXPECT_THROW(readTransmittanceParams(skinlab::SpecReader(bad, "scene.toml")), skinlab::InputError);
}

// The reference's through-light: the gain and its growth with the squared distance through the part (defaults fitted
// to the path tracer, docs/pathtraced.md), read and checked like every key; a bad value is one line naming the file
// and the key.
TEST(SssParams, ReferenceThroughLightKeys) {
    const SssParams defaults = readSss("[sss]\nmethod = \"reference\"\n");
    EXPECT_EQ(referenceParams(defaults).throughGain, (std::array<double, 3>{1.181, 5.727, 9.723}));
    EXPECT_EQ(referenceParams(defaults).throughGrowthPerMm2, (std::array<double, 3>{0.04, -0.04, 0.0}));
    const SssParams p = readSss("[sss]\nmethod = \"reference\"\nreference_through_gain = [1.72, 5.31, 9.44]\n"
                                "reference_through_growth_per_mm2 = [0, 0.0, -0.5]\n");
    EXPECT_EQ(referenceParams(p).throughGain, (std::array<double, 3>{1.72, 5.31, 9.44}));
    EXPECT_EQ(referenceParams(p).throughGrowthPerMm2, (std::array<double, 3>{0.0, 0.0, -0.5}));
    EXPECT_EQ(sssParamsFromJson(p.toJson()).toJson(), p.toJson());
    EXPECT_EQ(p.toJson().at("reference_through_growth_per_mm2"), nlohmann::json({0.0, 0.0, -0.5}));
    const std::string head = "[sss]\nmethod = \"reference\"\nreference_through_growth_per_mm2 = ";
    EXPECT_EQ(sssError(head + "[0.0, 0.2, 0.0]"),
              "scene.toml: sss.reference_through_growth_per_mm2: element 1: 0.2 is out of range [-1, 0.1]");
    EXPECT_EQ(sssError(head + "[0.0, 0.0, \"x\"]"),
              "scene.toml: sss.reference_through_growth_per_mm2: element 2: expected a number, got string \"x\"");
    EXPECT_EQ(sssError(head + "0.03"),
              "scene.toml: sss.reference_through_growth_per_mm2: expected an array of numbers, got float 0.03");
    EXPECT_EQ(sssError(head + "[0.03, 0.0]"),
              "scene.toml: sss.reference_through_growth_per_mm2: expected 3 numbers, got 2");
    EXPECT_EQ(sssError("[sss]\nmethod = \"reference\"\nreference_through_gain = [1.0, -1.0, 1.0]"),
              "scene.toml: sss.reference_through_gain: element 1: -1 is out of range [0, 100]");
    EXPECT_EQ(sssError("[sss]\nmethod = \"separable\"\nreference_through_growth_per_mm2 = [0.0, 0.0, 0.0]")
                  .rfind("scene.toml: sss.reference_through_growth_per_mm2: not a parameter of method 'separable'", 0),
              0u);
    for (const std::string& error : {sssError(head + "[0.0, 0.2, 0.0]"), sssError(head + "0.03")})
        EXPECT_EQ(error.find('\n'), std::string::npos) << error;
}

// Every method reads its own keys only: a key of another method is an error naming the key and the method, in a
// scene file and in the JSON form alike, and the resolved record holds the method's keys only.
TEST(SssParams, KeyOfAnotherMethodIsAnError) {
    EXPECT_EQ(sssError("[sss]\nmethod = \"separable\"\nartistic_falloff = [1.0, 0.5, 0.5]\n"),
              "scene.toml: sss.artistic_falloff: not a parameter of method 'separable' (its keys: width_mm, "
              "curvature_measure, curvature_reference_mm, samples, sampling, follow_surface_k, profile, material, "
              "follow_surface, cbf, cbf_lambda, lab_weight, extension_input, curvature, curvature_floor)");
    EXPECT_EQ(sssError("[sss]\nsamples = 31\n").rfind("scene.toml: sss.samples: not a parameter of method 'none'", 0),
              0u);
    EXPECT_EQ(sssError("[sss]\nmethod = \"reference\"\ncbf = true\n")
                  .rfind("scene.toml: sss.cbf: not a parameter of method 'reference'", 0),
              0u);
    EXPECT_EQ(sssError("[sss]\nmethod = \"pscbf\"\nprofile = \"burley\"\n")
                  .rfind("scene.toml: sss.profile: not a parameter of method 'pscbf'", 0),
              0u);
    EXPECT_THROW(sssParamsFromJson({{"method", "separable"}, {"artistic_strength", {1, 1, 1}}}), skinlab::InputError);
    // The common keys are accepted with every method.
    for (const MethodInfo& info : methodTable()) {
        const std::string text = "[sss]\nmethod = \"" + std::string(info.name) +
                                 "\"\nwidth_mm = 2.0\ncurvature_measure = \"screen\"\ncurvature_reference_mm = 30\n";
        EXPECT_EQ(sssError(text), "no error") << info.name;
        // toJson: exactly the method's keys, and they read back.
        SssParams p;
        p.method = info.method;
        const nlohmann::json json = p.toJson();
        EXPECT_EQ(json.size(), kCommonSssKeys.size() + info.keys.size() + info.ownKeys.size()) << info.name;
        for (const auto& [key, value] : json.items()) EXPECT_TRUE(methodUsesKey(info.method, key)) << key;
        EXPECT_EQ(sssParamsFromJson(json).toJson(), json) << info.name;
    }
}

// The method table: every row's identifier is its position, its name finds it and reads back; the built-in methods
// are there, "none" first (SssMethod{}), the screen-space ones in table order. Nothing here counts the methods, so
// adding one changes no line of this test.
TEST(SssParams, MethodTable) {
    const auto& table = methodTable();
    for (std::size_t i = 0; i < table.size(); ++i) {
        EXPECT_EQ(static_cast<std::size_t>(table[i].method), i);
        EXPECT_EQ(findMethod(table[i].name), &table[i]);
        EXPECT_EQ(methodId(table[i].name), table[i].method);
        EXPECT_EQ(methodName(table[i].method), table[i].name);
        EXPECT_EQ(readSss("[sss]\nmethod = \"" + std::string(table[i].name) + "\"\n").method, table[i].method);
        EXPECT_TRUE(table[i].model) << table[i].name;
    }
    EXPECT_EQ(findMethod("blur"), nullptr);
    EXPECT_EQ(methodName(SssMethod{}), "none");
    EXPECT_EQ(SssParams().method, methodId("none"));
    std::vector<std::string> screenSpace;
    for (const std::string name :
         {"none", "gaussian-sum", "separable", "artistic", "pscbf", "reference", "pathtraced", "eevee"}) {
        ASSERT_NE(findMethod(name), nullptr) << name;
        if (findMethod(name)->screenSpace()) screenSpace.push_back(name);
    }
    EXPECT_EQ(screenSpace, (std::vector<std::string>{"gaussian-sum", "separable", "artistic", "pscbf"}));
    std::vector<std::string> listed = screenSpaceMethodNames();
    for (const std::string& name : screenSpace) EXPECT_NE(std::find(listed.begin(), listed.end(), name), listed.end());
    // Interactive: what live tuning renders as a slider moves; the others run as background renders.
    for (const std::string name : {"none", "gaussian-sum", "separable", "artistic", "pscbf"})
        EXPECT_TRUE(findMethod(name)->interactive) << name;
    for (const std::string name : {"reference", "pathtraced", "eevee"})
        EXPECT_FALSE(findMethod(name)->interactive) << name;
}

namespace {
// The body rows of the first markdown table in docs/methods.md whose header row starts with `header`: per cell, the
// backticked key and method names in it ("the extension keys" stands for their list; other backticked text, such as
// a table name, is left out).
std::vector<std::vector<std::vector<std::string>>> docTable(const std::string& header) {
    std::ifstream in(std::string(SKINLAB_SOURCE_DIR) + "/docs/methods.md");
    std::string line;
    bool inTable = false;
    std::vector<std::vector<std::vector<std::string>>> rows;
    while (std::getline(in, line)) {
        if (!inTable) {
            inTable = line.rfind(header, 0) == 0;
            continue;
        }
        if (line.rfind("|", 0) != 0) break;
        if (line.rfind("|---", 0) == 0) continue;
        std::vector<std::vector<std::string>> cells;
        std::stringstream row(line.substr(1));
        std::string cell;
        while (std::getline(row, cell, '|')) {
            std::vector<std::string> names;
            for (std::size_t at = cell.find('`'); at != std::string::npos; at = cell.find('`', at + 1)) {
                const std::size_t end = cell.find('`', at + 1);
                if (end == std::string::npos) break;
                const std::string name = cell.substr(at + 1, end - at - 1);
                if (name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_-") == std::string::npos)
                    names.push_back(name);
                at = end;
            }
            if (cell.find("the extension keys") != std::string::npos)
                for (const char* k :
                     {"cbf", "cbf_lambda", "lab_weight", "extension_input", "curvature", "curvature_floor"})
                    names.emplace_back(k);
            cells.push_back(names);
        }
        rows.push_back(cells);
    }
    return rows;
}
} // namespace

// The docs' key tables follow the declarations: every declared [sss] key has a row in "Parameters: [sss]", and the
// table of each method's own keys lists exactly the keys its row of the method table declares.
TEST(SssParams, MethodsPageTablesFollowTheDeclarations) {
    std::set<std::string> documented;
    for (const auto& row : docTable("| key |"))
        if (!row.empty()) documented.insert(row[0].begin(), row[0].end());
    ASSERT_FALSE(documented.empty()) << "no [sss] key table in docs/methods.md";
    for (const SssKey& key : sssKeyTable()) EXPECT_TRUE(documented.count(std::string(key.name))) << key.name;

    std::map<std::string, std::set<std::string>> ownKeys; // method → keys, from the page
    for (const auto& row : docTable("| method | its own keys |"))
        if (row.size() >= 2)
            for (const auto& method : row[0]) ownKeys[method].insert(row[1].begin(), row[1].end());
    ASSERT_FALSE(ownKeys.empty()) << "no '| method | its own keys |' table in docs/methods.md";
    for (const MethodInfo& info : methodTable()) {
        ASSERT_TRUE(ownKeys.count(std::string(info.name))) << info.name << " has no row";
        std::set<std::string> declared;
        for (const std::string_view key : methodKeys(info.method))
            if (std::find(kCommonSssKeys.begin(), kCommonSssKeys.end(), key) == kCommonSssKeys.end())
                declared.emplace(key);
        EXPECT_EQ(ownKeys.at(std::string(info.name)), declared) << info.name;
    }
}
