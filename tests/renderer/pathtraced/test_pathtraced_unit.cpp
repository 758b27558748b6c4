// renderer/pathtraced without Blender: the parameters, the scene written for Blender (lights in Blender's units,
// the environment lookup, open and closed surfaces), the child process's errors, and the profile-fit arithmetic.
#include "common/error.h"
#include "common/files.h"
#include "renderer/pathtraced/blender_process.h"
#include "renderer/pathtraced/blender_scene.h"
#include "renderer/pathtraced/cycles_render.h"
#include "renderer/sss/pathtraced_params.h"
#include "renderer/pathtraced/profile_fit.h"
#include "renderer/scene/builtin_geometry.h"
#include "renderer/scene/environment.h"
#include "renderer/scene/texture.h"
#include "renderer/sss/sss_params.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <functional>
#include <random>

using namespace skinlab;
using namespace skinlab::renderer;
using namespace skinlab::renderer::pathtraced;

namespace {
constexpr double kPi = 3.14159265358979323846;

std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no InputError)";
}

struct Exported {
    SceneSpec spec;
    Model model;
    nlohmann::json json;
};

// The inputs the renderer would hand Blender for `model` under `spec` (materials as the model has them).
BlenderSceneInputs inputsFor(const SceneSpec& spec, const Model& model) {
    BlenderSceneInputs inputs;
    inputs.spec = &spec;
    inputs.model = &model;
    for (const SubMesh& part : model.parts) {
        const MeshMaterial& m = model.materials[part.material];
        inputs.partMaterials.push_back({m.albedo, m.skin ? 1.0f : 0.0f, m.glossiness, m.specularIntensity});
    }
    inputs.params = spec.pathtraced;
    return inputs;
}

Exported exportScene(const std::string& scene, std::vector<std::string> overrides) {
    Exported e;
    overrides.push_back("sss.method=\"pathtraced\"");
    e.spec = loadSceneSpec(scene, overrides, {});
    e.model =
        e.spec.modelSource == "builtin:halo" ? makeHaloScene(static_cast<float>(e.spec.depthGapMm)) : makeBleedScene();
    BlenderSceneInputs inputs = inputsFor(e.spec, e.model);
    inputs.camera = frameCamera(e.spec.camera, e.model.boundsMin, e.model.boundsMax, e.model.boundsMin,
                                e.model.boundsMax, e.spec.frameWidth, e.spec.frameHeight, e.spec.window);
    inputs.sssWidthMm = e.spec.sss.widthMm;
    e.json = blenderSceneJson(inputs, "mesh.bin", "cycles.exr", "cycles.json");
    return e;
}
} // namespace

TEST(PathtracedParams, DefaultsAndStrictKeys) {
    const SceneSpec spec = loadSceneSpec("builtin:halo", {"sss.method=\"pathtraced\""}, {});
    EXPECT_EQ(spec.resolved.at("pathtraced").at("samples"), 64);
    EXPECT_EQ(spec.resolved.at("pathtraced").at("seed"), 0);
    // Other methods do not record the table (their images do not depend on it).
    EXPECT_FALSE(loadSceneSpec("builtin:halo", {}, {}).resolved.contains("pathtraced"));
    const std::string zero = errorOf([] { loadSceneSpec("builtin:halo", {"pathtraced.samples=0"}, {}); });
    EXPECT_NE(zero.find("pathtraced.samples"), std::string::npos) << zero;
    const std::string unknown = errorOf([] { loadSceneSpec("builtin:halo", {"pathtraced.sample=4"}, {}); });
    EXPECT_NE(unknown.find("pathtraced.sample"), std::string::npos) << unknown;
    const std::string radius =
        errorOf([] { loadSceneSpec("builtin:halo", {"pathtraced.radius_mm=[1.0, -1.0, 1.0]"}, {}); });
    EXPECT_NE(radius.find("pathtraced.radius_mm"), std::string::npos) << radius;
    // The JSON form round-trips.
    PathtracedParams p;
    p.samples = 7;
    p.radiusMm = {2.0, 1.0, 0.5};
    EXPECT_EQ(pathtracedParamsFromJson(p.toJson()).toJson(), p.toJson());
}

TEST(PathtracedParams, SpecularSourceRasterizerRendersNoCyclesSpecular) {
    // "cycles" (default): the Principled specular of every part follows the material; "rasterizer": 0 (the beauty
    // gets the rasterizer's specular pass instead, renderer/renderer.cpp); anything else is an error naming the key.
    const Exported own = exportScene("builtin:halo", {});
    EXPECT_EQ(own.spec.resolved.at("pathtraced").at("specular_source"), "cycles");
    EXPECT_GT(own.json.at("materials").at(0).at("specular").get<double>(), 0.0);
    const Exported borrowed = exportScene("builtin:halo", {"pathtraced.specular_source=\"rasterizer\""});
    for (const auto& material : borrowed.json.at("materials")) EXPECT_EQ(material.at("specular").get<double>(), 0.0);
    const std::string bad =
        errorOf([] { loadSceneSpec("builtin:halo", {"pathtraced.specular_source=\"glossy\""}, {}); });
    EXPECT_NE(bad.find("pathtraced.specular_source"), std::string::npos) << bad;
    EXPECT_NE(bad.find("glossy"), std::string::npos) << bad;
}

TEST(PathtracedParams, EnvironmentShadowOffRendersTheEnvironmentInItsOwnPass) {
    // Default: the environment is shadowed like any light, one pass. false: with lights, a second output for the
    // unshadowed environment; without lights, one pass (cycles_scene.py turns the shadows off in it).
    const Exported shadowed = exportScene("builtin:halo", {});
    EXPECT_TRUE(shadowed.json.at("world").at("shadow").get<bool>());
    EXPECT_FALSE(shadowed.json.contains("environment_output"));
    const Exported open = exportScene("builtin:halo", {"pathtraced.environment_shadow=false"});
    EXPECT_EQ(open.spec.resolved.at("pathtraced").at("environment_shadow"), false);
    EXPECT_FALSE(open.json.at("world").at("shadow").get<bool>());
    ASSERT_FALSE(open.spec.lights.empty());
    EXPECT_EQ(open.json.at("environment_output"), std::string(kEnvironmentOutput));
    const Exported dark = exportScene("builtin:halo", {"pathtraced.environment_shadow=false", "lights=[]"});
    EXPECT_TRUE(dark.spec.lights.empty());
    EXPECT_FALSE(dark.json.contains("environment_output"));
    const std::string bad = errorOf([] { loadSceneSpec("builtin:halo", {"pathtraced.environment_shadow=2"}, {}); });
    EXPECT_NE(bad.find("pathtraced.environment_shadow"), std::string::npos) << bad;
}

TEST(BlenderScene, LightsInBlenderUnits) {
    // builtin:head: a spot (intensity 1.6, colour [1, 0.95, 0.88]) and a directional light (0.25, [0.85, 0.9, 1]).
    const SceneSpec spec = loadSceneSpec("builtin:head", {"sss.method=\"pathtraced\""}, {});
    Model model = makeBleedScene(); // any model: only the lights are checked here
    BlenderSceneInputs inputs;
    inputs.spec = &spec;
    inputs.model = &model;
    inputs.partMaterials.resize(model.parts.size());
    const nlohmann::json json = blenderSceneJson(inputs, "m", "o", "r");
    const auto& spot = json.at("lights").at(0);
    const auto& sun = json.at("lights").at(1);
    EXPECT_EQ(spot.at("type"), "spot");
    const double d = glm::length(spec.lights[0].target - spec.lights[0].position);
    // Irradiance π L_c at the target distance: power = 4π · π L_c d².
    EXPECT_NEAR(spot.at("power").get<double>(), 4.0 * kPi * kPi * 1.6 * d * d, 1e-6 * spot.at("power").get<double>());
    EXPECT_NEAR(spot.at("spot_size_rad").get<double>(), 2.0 * 25.0 * kPi / 180.0, 1e-9);
    const double cosInner = std::cos(15.0 * kPi / 180.0), cosOuter = std::cos(25.0 * kPi / 180.0);
    EXPECT_NEAR(spot.at("spot_blend").get<double>(), (cosInner - cosOuter) / (1.0 - cosOuter), 1e-9);
    EXPECT_EQ(sun.at("type"), "sun");
    EXPECT_NEAR(sun.at("strength").get<double>(), kPi * 0.25, 1e-6); // colour max 1: strength π L_c
    EXPECT_NEAR(sun.at("color").at(0).get<double>(), 0.85, 1e-6);
    EXPECT_FALSE(sun.at("shadow").get<bool>());
    EXPECT_NEAR(principledRoughness(0.5), std::pow(2.0 / (8192.0 * std::pow(0.5, 5.0) + 2.0), 0.25), 1e-12);
    EXPECT_NEAR(principledSpecular(0.028), 0.35, 1e-12);
}

// render.window: Blender renders the window's pixels with the frame's focal length in pixels (the window's vertical
// field of view) and the lens shift that moves the image off the view axis (units of the image height, vertical fit).
TEST(BlenderScene, WindowIsTheFieldOfViewAndLensShiftOfTheSameCamera) {
    const Exported whole = exportScene("builtin:halo", {"render.width=256", "render.height=256"});
    EXPECT_FALSE(whole.json.at("camera").contains("shift_x"));
    const Exported part = exportScene("builtin:halo", {"render.width=256", "render.height=256",
                                                       "render.window={ x = 64, y = 32, width = 96, height = 64 }"});
    EXPECT_EQ(part.json.at("settings").at("width"), 96);
    EXPECT_EQ(part.json.at("settings").at("height"), 64);
    const double f = 128.0 / std::tan(15.0 * kPi / 180.0); // the frame's f_px (fov_deg 30)
    EXPECT_NEAR(part.json.at("camera").at("fov_y_rad").get<double>(), 2.0 * std::atan(32.0 / f), 1e-6);
    // The window's centre lies 16 px left of and 64 px above the frame's: shifts −16/64 and 64/64.
    EXPECT_NEAR(part.json.at("camera").at("shift_x").get<double>(), -0.25, 1e-6);
    EXPECT_NEAR(part.json.at("camera").at("shift_y").get<double>(), 1.0, 1e-6);
    EXPECT_EQ(part.json.at("camera").at("view_to_world"), whole.json.at("camera").at("view_to_world"));
}

TEST(BlenderScene, EnvironmentLookupMatchesSkinlabConvention) {
    // Blender's equirectangular lookup of D = rows · d must give skinlab's (u, v) of the rotated direction.
    const double rotation = 37.0;
    const glm::mat3 environmentFromWorld(
        glm::rotate(glm::mat4(1.0f), static_cast<float>(-rotation * kPi / 180.0), glm::vec3(0, 1, 0)));
    SceneSpec spec = loadSceneSpec("builtin:halo", {"sss.method=\"pathtraced\""}, {});
    spec.environment.file = "/nonexistent/sky.hdr"; // only its presence matters to the JSON
    spec.environment.rotationDeg = rotation;
    Model model = makeBleedScene();
    BlenderSceneInputs inputs;
    inputs.spec = &spec;
    inputs.model = &model;
    inputs.partMaterials.resize(model.parts.size());
    const nlohmann::json rows = blenderSceneJson(inputs, "m", "o", "r").at("world").at("lookup_rows");
    std::mt19937 random(5);
    std::normal_distribution<float> normal;
    for (int i = 0; i < 200; ++i) {
        const glm::vec3 d = glm::normalize(glm::vec3(normal(random), normal(random), normal(random)));
        glm::dvec3 D;
        for (int r = 0; r < 3; ++r)
            D[r] = rows[r][0].get<double>() * d.x + rows[r][1].get<double>() * d.y + rows[r][2].get<double>() * d.z;
        // Blender (intern/cycles/kernel/geom: direction_to_equirectangular): u = -atan2(y, x)/2π + 0.5,
        // v = atan2(z, hypot(x, y))/π + 0.5 with v = 1 the image's top row.
        double u = -std::atan2(D.y, D.x) / (2.0 * kPi) + 0.5;
        const double vTop = 1.0 - (std::atan2(D.z, std::hypot(D.x, D.y)) / kPi + 0.5);
        const glm::vec2 expected = equirectCoordinates(environmentFromWorld * d);
        double du = std::abs(u - expected.x);
        du = std::min(du, 1.0 - du); // the seam
        EXPECT_LT(du, 1e-5) << i;
        EXPECT_NEAR(vTop, expected.y, 1e-5) << i;
    }
}

TEST(BlenderScene, PartsAndRadii) {
    const Model halo = makeHaloScene(200.0f);
    EXPECT_TRUE(isClosedSurface(halo, halo.parts[0]));  // the skin sphere
    EXPECT_FALSE(isClosedSurface(halo, halo.parts[1])); // the backdrop plane
    const Exported bleed = exportScene("builtin:bleed", {});
    EXPECT_EQ(bleed.json.at("mesh").at("parts").size(), bleed.model.parts.size());
    for (const auto& part : bleed.json.at("mesh").at("parts")) EXPECT_FALSE(part.at("closed").get<bool>());
    // Radii: mm at width 3 mm, scaled by width_mm / 3 and divided by mm_per_unit.
    const Exported wide =
        exportScene("builtin:halo", {"sss.width_mm=6.0", "mm_per_unit=2.0", "pathtraced.radius_mm=[3.0, 2.0, 1.0]"});
    EXPECT_NEAR(wide.json.at("materials").at(0).at("radius").at(0).get<double>(), 3.0 * 2.0 / 2.0, 1e-9);
    EXPECT_NEAR(wide.json.at("materials").at(0).at("radius").at(2).get<double>(), 1.0 * 2.0 / 2.0, 1e-9);
}

TEST(BlenderScene, TheModelsGeneratedMapsAreWrittenUnlessTheSpecNamesFiles) {
    // A model's in-memory maps (builtin:head's skin detail) go to Blender as linear EXRs beside the scene, as the
    // rasterizer uses them: only where the spec names no file of its own.
    SceneSpec spec = loadSceneSpec("builtin:halo", {"sss.method=\"pathtraced\""}, {});
    Model model = makeHaloScene(200.0f);
    Image albedo;
    albedo.width = 3, albedo.height = 2;
    for (int i = 0; i < 6; ++i) albedo.pixels.insert(albedo.pixels.end(), {0.5f + 0.1f * i, 1.25f, 0.01f * i, 1.0f});
    model.albedoMap = std::make_shared<const Image>(albedo);
    Image normal = albedo;
    for (float& v : normal.pixels) v = 0.5f;
    model.normalMap = std::make_shared<const Image>(normal);
    const BlenderSceneInputs inputs = inputsFor(spec, model);
    const nlohmann::json json = blenderSceneJson(inputs, "mesh.bin", "cycles.exr", "cycles.json");
    EXPECT_EQ(json.at("textures").at("albedo"), "model-albedo.exr");
    EXPECT_EQ(json.at("textures").at("albedo_colorspace"), "Non-Color");
    EXPECT_EQ(json.at("textures").at("normal"), "model-normal.exr");
    const std::filesystem::path folder = makeWorkFolder("skinlab-test-model-maps");
    writeBlenderScene(folder, inputs);
    int width = 0, height = 0;
    const auto written = readExrChannels(folder / "model-albedo.exr", width, height);
    std::filesystem::remove_all(folder);
    ASSERT_EQ(width, 3);
    ASSERT_EQ(height, 2);
    for (int i = 0; i < 6; ++i)
        for (int c = 0; c < 3; ++c)
            EXPECT_FLOAT_EQ(written.at(std::string(1, "RGB"[c]))[i], albedo.pixels[i * 4 + c]) << i << " " << c;
    // A spec's file replaces the model's map (the albedo here); the other map still comes from the model.
    spec.textures.albedo = "skin.png";
    const nlohmann::json replaced = blenderSceneJson(inputs, "mesh.bin", "cycles.exr", "cycles.json");
    EXPECT_EQ(replaced.at("textures").at("albedo"), "skin.png");
    EXPECT_FALSE(replaced.at("textures").contains("albedo_colorspace"));
    EXPECT_EQ(replaced.at("textures").at("normal"), "model-normal.exr");
}

TEST(PathtracedParams, RadiusModelKeyIsStrict) {
    // Default "albedo", recorded in the resolved parameters and the JSON form; anything else names file and key.
    const SceneSpec spec = loadSceneSpec("builtin:halo", {"sss.method=\"pathtraced\""}, {});
    EXPECT_EQ(spec.pathtraced.radiusModel, "albedo");
    EXPECT_EQ(spec.resolved.at("pathtraced").at("radius_model"), "albedo");
    EXPECT_EQ(loadSceneSpec("builtin:halo", {"pathtraced.radius_model=\"constant\""}, {}).pathtraced.radiusModel,
              "constant");
    const std::string bad = errorOf([] { loadSceneSpec("builtin:halo", {"pathtraced.radius_model=\"linear\""}, {}); });
    EXPECT_NE(bad.find("pathtraced.radius_model"), std::string::npos) << bad;
    EXPECT_NE(bad.find("linear"), std::string::npos) << bad;
    EXPECT_EQ(bad.find('\n'), std::string::npos) << bad;
    const std::string number = errorOf([] { loadSceneSpec("builtin:halo", {"pathtraced.radius_model=1"}, {}); });
    EXPECT_NE(number.find("pathtraced.radius_model"), std::string::npos) << number;
    PathtracedParams p;
    p.radiusModel = "constant";
    EXPECT_EQ(p.toJson().at("radius_model"), "constant");
    EXPECT_EQ(pathtracedParamsFromJson(p.toJson()).radiusModel, "constant");
    const std::string json = errorOf([] { pathtracedParamsFromJson({{"radius_model", "table"}}, "scene.json"); });
    EXPECT_NE(json.find("radius_model"), std::string::npos) << json;
}

TEST(PathtracedParams, DiffuseModelKeyIsStrictAndReachesEveryMaterial) {
    // Default "lambert" (the rasterizer's diffuse model), recorded and written into every part's material for the
    // Blender script; "principled" keeps Blender's Principled BSDF; anything else is a one-line error naming the key.
    const Exported own = exportScene("builtin:bleed", {});
    EXPECT_EQ(own.spec.pathtraced.diffuse, "lambert");
    EXPECT_EQ(own.spec.resolved.at("pathtraced").at("diffuse"), "lambert");
    for (const auto& material : own.json.at("materials")) EXPECT_EQ(material.at("diffuse"), "lambert");
    const Exported principled = exportScene("builtin:bleed", {"pathtraced.diffuse=\"principled\""});
    for (const auto& material : principled.json.at("materials")) EXPECT_EQ(material.at("diffuse"), "principled");
    const std::string bad = errorOf([] { loadSceneSpec("builtin:halo", {"pathtraced.diffuse=\"burley\""}, {}); });
    EXPECT_NE(bad.find("pathtraced.diffuse"), std::string::npos) << bad;
    EXPECT_NE(bad.find("burley"), std::string::npos) << bad;
    EXPECT_EQ(bad.find('\n'), std::string::npos) << bad;
    PathtracedParams p;
    p.diffuse = "principled";
    EXPECT_EQ(pathtracedParamsFromJson(p.toJson()).diffuse, "principled");
}

TEST(PathtracedParams, AlbedoRadiusTableIsPiecewiseLinearAndClamped) {
    const AlbedoRadiusTable& table = albedoRadiusTable();
    ASSERT_GE(table.albedo.size(), 2u);
    // It covers at least 0.03 … 0.9 (down to the darkest skin tone's green), in ascending albedo.
    EXPECT_LE(table.albedo.front(), 0.03 + 1e-12);
    EXPECT_GE(table.albedo.back(), 0.9 - 1e-12);
    for (std::size_t k = 1; k < table.albedo.size(); ++k) EXPECT_GT(table.albedo[k], table.albedo[k - 1]);
    for (int c = 0; c < 3; ++c) {
        const auto& radius = table.radiusMm[static_cast<std::size_t>(c)];
        ASSERT_EQ(radius.size(), table.albedo.size());
        for (std::size_t k = 0; k < table.albedo.size(); ++k) {
            // The values at the knots, and linear between neighbours.
            EXPECT_DOUBLE_EQ(tableRadiusMm(table, c, table.albedo[k]), radius[k]);
            if (k + 1 < table.albedo.size()) {
                const double middle = 0.5 * (table.albedo[k] + table.albedo[k + 1]);
                EXPECT_NEAR(tableRadiusMm(table, c, middle), 0.5 * (radius[k] + radius[k + 1]), 1e-12);
                // A brighter walk scatters further: the matched radius falls with the albedo.
                EXPECT_LT(radius[k + 1], radius[k]) << c << " at " << table.albedo[k];
            }
        }
        // Constant beyond the ends (NaN takes the first value).
        EXPECT_DOUBLE_EQ(tableRadiusMm(table, c, 0.0), radius.front());
        EXPECT_DOUBLE_EQ(tableRadiusMm(table, c, -1.0), radius.front());
        EXPECT_DOUBLE_EQ(tableRadiusMm(table, c, 1.0), radius.back());
        EXPECT_DOUBLE_EQ(tableRadiusMm(table, c, 5.0), radius.back());
        EXPECT_DOUBLE_EQ(tableRadiusMm(table, c, std::nan("")), radius.front());
        // Red scatters furthest at every albedo, blue least.
        if (c > 0) {
            for (double a = 0.0; a <= 1.0; a += 0.01)
                EXPECT_GT(tableRadiusMm(table, c - 1, a), tableRadiusMm(table, c, a)) << c << " at " << a;
        }
    }
    // The table agrees with the single-albedo fit at the built-in skin's colour (the fits' noise: a few %).
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(tableRadiusMm(table, c, kFitAlbedo[static_cast<std::size_t>(c)]) /
                        fittedRadiusMm()[static_cast<std::size_t>(c)],
                    1.0, 0.05)
            << c;
}

TEST(PathtracedParams, RadiusAtAlbedoFollowsTheModel) {
    const AlbedoRadiusTable& table = albedoRadiusTable();
    PathtracedParams albedo; // default: the albedo model
    PathtracedParams constant;
    constant.radiusModel = "constant";
    for (int c = 0; c < 3; ++c) {
        const auto i = static_cast<std::size_t>(c);
        // radius_mm is the radius at the built-in skin's colour in both models.
        EXPECT_NEAR(radiusAtAlbedoMm(albedo, c, kFitAlbedo[i]), albedo.radiusMm[i], 1e-12);
        EXPECT_DOUBLE_EQ(radiusAtAlbedoMm(constant, c, kFitAlbedo[i]), constant.radiusMm[i]);
        for (const double a : {0.05, 0.1, 0.3, 0.5, 0.8, 0.9, 1.0}) {
            EXPECT_DOUBLE_EQ(radiusAtAlbedoMm(constant, c, a), constant.radiusMm[i]);
            // Elsewhere the table's shape, scaled by radius_mm over its value at the skin's colour.
            EXPECT_NEAR(radiusAtAlbedoMm(albedo, c, a),
                        albedo.radiusMm[i] * tableRadiusMm(table, c, a) / tableRadiusMm(table, c, kFitAlbedo[i]),
                        1e-12);
        }
        // Darker skin: a longer radius than the constant one; lighter: a shorter one.
        EXPECT_GT(radiusAtAlbedoMm(albedo, c, 0.2), radiusAtAlbedoMm(constant, c, 0.2));
        EXPECT_LT(radiusAtAlbedoMm(albedo, c, 0.9), radiusAtAlbedoMm(constant, c, 0.9));
        // radius_mm multiplies the whole curve.
        PathtracedParams doubled = albedo;
        doubled.radiusMm[i] *= 2.0;
        EXPECT_NEAR(radiusAtAlbedoMm(doubled, c, 0.3), 2.0 * radiusAtAlbedoMm(albedo, c, 0.3), 1e-12);
    }
}

TEST(BlenderScene, AlbedoRadiusModelWritesTheScaledTable) {
    // radius_model "albedo" (default): every material carries the table, scaled like the constant radius
    // (width_mm / 3 / mm_per_unit) and by radius_mm over the table at the skin's colour; "constant": none.
    const Exported wide = exportScene("builtin:halo", {"sss.width_mm=6.0", "mm_per_unit=2.0"});
    const AlbedoRadiusTable& table = albedoRadiusTable();
    const PathtracedParams defaults;
    ASSERT_FALSE(wide.json.at("materials").empty());
    for (const auto& material : wide.json.at("materials")) {
        ASSERT_TRUE(material.contains("radius_table")) << material.dump();
        const auto& written = material.at("radius_table");
        EXPECT_EQ(written.at("albedo").get<std::vector<double>>(), table.albedo);
        for (int c = 0; c < 3; ++c)
            for (std::size_t k = 0; k < table.albedo.size(); ++k)
                EXPECT_NEAR(written.at("radius").at(c).at(k).get<double>(),
                            radiusAtAlbedoMm(defaults, c, table.albedo[k]) * 6.0 / 3.0 / 2.0, 1e-9);
        // The constant radius stays (the value at the skin's colour, what EEVEE and radius_model "constant" use).
        EXPECT_NEAR(material.at("radius").at(0).get<double>(), defaults.radiusMm[0] * 6.0 / 3.0 / 2.0, 1e-9);
    }
    const Exported constant = exportScene("builtin:halo", {"pathtraced.radius_model=\"constant\""});
    for (const auto& material : constant.json.at("materials")) EXPECT_FALSE(material.contains("radius_table"));
    // The script maps the subsurface colour through the table into the Subsurface Radius input.
    const std::string_view script = cyclesScript();
    EXPECT_NE(script.find("radius_from_albedo(nodes, links, albedo, description[\"radius_table\"])"),
              std::string_view::npos);
    EXPECT_NE(script.find("bsdf.inputs[\"Subsurface Radius\"]"), std::string_view::npos);
}

TEST(BlenderProcess, MissingAndFailingProgramsAreOneLineErrors) {
    const std::filesystem::path folder = makeWorkFolder("skinlab-test-process");
    const std::string missing =
        errorOf([&] { runBlender("skinlab-no-such-blender", folder / "x.py", {}, folder, folder / "blender.log"); });
    EXPECT_NE(missing.find("skinlab-no-such-blender"), std::string::npos) << missing;
    EXPECT_NE(missing.find("not found"), std::string::npos) << missing;
    EXPECT_EQ(missing.find('\n'), std::string::npos) << missing;
    // A program that runs and fails: the error names it, its exit status and the log.
    const std::string failing =
        errorOf([&] { runBlender("false", folder / "x.py", {}, folder, folder / "blender.log"); });
    EXPECT_NE(failing.find("exit status 1"), std::string::npos) << failing;
    EXPECT_NE(failing.find((folder / "blender.log").string()), std::string::npos) << failing;
    EXPECT_EQ(failing.find('\n'), std::string::npos) << failing;
    std::filesystem::remove_all(folder);
}

TEST(ProfileFit, DeonEdgeResponseKnownValues) {
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(deonEdgeResponse(c, 0.0), 0.5, 1e-9); // each channel's weights sum to 1
        EXPECT_LT(deonEdgeResponse(c, 20.0), 1e-9);
    }
    // Red has the widest tail (d'Eon's 7.41 mm² lobe): at 2 mm red keeps more than green and blue.
    EXPECT_GT(deonEdgeResponse(0, 2.0), deonEdgeResponse(1, 2.0));
    EXPECT_GT(deonEdgeResponse(1, 2.0), deonEdgeResponse(2, 2.0));
}

TEST(ProfileFit, RecoversTheScaleOfASyntheticResponse) {
    // A "measured" response that is d'Eon's own, stretched by k: the fit must return radius k per channel.
    const std::array<double, 3> k{2.5, 0.8, 0.4};
    EdgeResponse response;
    const double pixel = 0.005;
    for (int i = 0; i < 8000; ++i) response.xMm.push_back((i + 0.5) * pixel);
    for (int c = 0; c < 3; ++c)
        for (double x : response.xMm)
            response.value[static_cast<std::size_t>(c)].push_back(
                deonEdgeResponse(c, x * k[static_cast<std::size_t>(c)]));
    const ProfileFit fit = fitRadii(response, {1.0, 1.0, 1.0});
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(fit.radiusMm[static_cast<std::size_t>(c)], k[static_cast<std::size_t>(c)],
                    1e-3 * k[static_cast<std::size_t>(c)])
            << c;
        EXPECT_LT(fit.rmsError[static_cast<std::size_t>(c)], 1e-4) << c;
        EXPECT_GT(fit.initialRmsError[static_cast<std::size_t>(c)], fit.rmsError[static_cast<std::size_t>(c)]) << c;
    }
}

TEST(ProfileFit, WidthsOfAStretchedDeonResponse) {
    // d'Eon's widths: ∫E = Σ w σ / √(2π) (checked by quadrature) and E(crossing) = 0.1.
    for (int c = 0; c < 3; ++c) {
        double quadrature = 0.0;
        for (double x = 0.00005; x < 30.0; x += 0.0001) quadrature += deonEdgeResponse(c, x) * 0.0001;
        EXPECT_NEAR(deonEdgeIntegral(c), quadrature, 1e-4 * quadrature) << c;
        EXPECT_NEAR(deonEdgeResponse(c, deonCrossing(c, 0.1)), 0.1, 1e-9) << c;
    }
    // A response that is d'Eon's stretched by k: at radius k every error vanishes, at radius 1.2 k the widths are
    // 20 % too wide.
    const std::array<double, 3> k{2.5, 0.8, 0.4};
    EdgeResponse response;
    for (int i = 0; i < 16000; ++i) response.xMm.push_back((i + 0.5) * 0.0025);
    for (int c = 0; c < 3; ++c)
        for (double x : response.xMm)
            response.value[static_cast<std::size_t>(c)].push_back(
                deonEdgeResponse(c, x * k[static_cast<std::size_t>(c)]));
    const ProfileMatch exact = matchProfile(response, k);
    const ProfileMatch wide = matchProfile(response, {1.2 * k[0], 1.2 * k[1], 1.2 * k[2]});
    for (std::size_t c = 0; c < 3; ++c) {
        EXPECT_LT(exact.rmsError[c], 1e-4) << c;
        EXPECT_NEAR(exact.integralError[c], 0.0, 2e-3) << c;
        EXPECT_NEAR(exact.crossingError[c], 0.0, 2e-3) << c;
        EXPECT_NEAR(wide.integralError[c], 0.2, 3e-3) << c;
        EXPECT_NEAR(wide.crossingError[c], 0.2, 3e-3) << c;
        EXPECT_GT(wide.rmsError[c], exact.rmsError[c]) << c;
    }
}

TEST(ProfileFit, SmoothRadiiFollowsASmoothCurveAndReadsBackTheCsv) {
    // ln r exactly cubic in the albedo: reproduced with no residual; noise of ±2 % is reduced.
    std::vector<double> albedo, exact, noisy;
    for (int k = 0; k <= 16; ++k) {
        const double a = 0.1 + 0.05 * k;
        albedo.push_back(a);
        exact.push_back(std::exp(3.0 - 2.0 * a + 0.5 * a * a - 0.3 * a * a * a));
        noisy.push_back(exact.back() * (k % 2 == 0 ? 1.02 : 0.98));
    }
    double residual = 1.0;
    const std::vector<double> same = smoothRadii(albedo, exact, 3, &residual);
    EXPECT_LT(residual, 1e-9);
    for (std::size_t k = 0; k < albedo.size(); ++k) EXPECT_NEAR(same[k], exact[k], 1e-9 * exact[k]);
    const std::vector<double> smoothed = smoothRadii(albedo, noisy, 3, &residual);
    EXPECT_NEAR(residual, 0.02, 0.002);
    for (std::size_t k = 1; k + 1 < albedo.size(); ++k) EXPECT_NEAR(smoothed[k] / exact[k], 1.0, 0.01) << k;
    EXPECT_THROW(smoothRadii({0.1, 0.2}, {1.0, 2.0}, 3), InputError);
    // edge_response.csv as fit-profile writes it.
    const std::filesystem::path folder = makeWorkFolder("skinlab-test-csv");
    writeFileAtomic(folder / "edge_response.csv", "x_mm_at_radius_1mm,E_R,E_G,E_B\n0.001,0.4,0.3,0.2\n0.003,0.3,"
                                                  "0.2,0.1\n");
    const EdgeResponse read = readEdgeResponseCsv(folder / "edge_response.csv");
    ASSERT_EQ(read.xMm.size(), 2u);
    EXPECT_DOUBLE_EQ(read.xMm[1], 0.003);
    EXPECT_DOUBLE_EQ(read.value[2][1], 0.1);
    writeFileAtomic(folder / "bad.csv", "x,E_R,E_G,E_B\n0.001,0.4\n0.002,0.1,0.1,0.1\n");
    const std::string bad = errorOf([&] { readEdgeResponseCsv(folder / "bad.csv"); });
    EXPECT_NE(bad.find("bad.csv:2"), std::string::npos) << bad;
    std::filesystem::remove_all(folder);
}
