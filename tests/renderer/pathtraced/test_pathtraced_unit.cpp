// renderer/pathtraced without Blender: the parameters, the scene written for Blender (lights in Blender's units,
// the environment lookup, open and closed surfaces), the child process's errors, and the profile-fit arithmetic.
#include "common/error.h"
#include "renderer/pathtraced/blender_process.h"
#include "renderer/pathtraced/blender_scene.h"
#include "renderer/pathtraced/cycles_render.h"
#include "renderer/sss/pathtraced_params.h"
#include "renderer/pathtraced/profile_fit.h"
#include "renderer/scene/builtin_geometry.h"
#include "renderer/scene/environment.h"
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

Exported exportScene(const std::string& scene, std::vector<std::string> overrides) {
    Exported e;
    overrides.push_back("sss.method=\"pathtraced\"");
    e.spec = loadSceneSpec(scene, overrides, {});
    e.model =
        e.spec.modelSource == "builtin:halo" ? makeHaloScene(static_cast<float>(e.spec.depthGapMm)) : makeBleedScene();
    BlenderSceneInputs inputs;
    inputs.spec = &e.spec;
    inputs.model = &e.model;
    for (const SubMesh& part : e.model.parts) {
        const MeshMaterial& m = e.model.materials[part.material];
        inputs.partMaterials.push_back({m.albedo, m.skin ? 1.0f : 0.0f, m.glossiness, m.specularIntensity});
    }
    inputs.camera = frameCamera(e.spec.camera, e.model.boundsMin, e.model.boundsMax, e.model.boundsMin,
                                e.model.boundsMax, e.spec.width, e.spec.height);
    inputs.params = e.spec.pathtraced;
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
