// sss.method = "eevee" without Blender: the [eevee] table (defaults, strict keys, one-line errors, JSON form), the
// scene written for EEVEE (engine, settings, radii), and the edge response of EEVEE's Christensen–Burley kernel
// with the radii fitted to d'Eon's profile.
#include "common/error.h"
#include "renderer/pathtraced/blender_scene.h"
#include "renderer/sss/eevee_params.h"
#include "renderer/pathtraced/profile_fit.h"
#include "renderer/scene/builtin_geometry.h"
#include "renderer/scene/scene_spec.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

using namespace skinlab;
using namespace skinlab::renderer;
using namespace skinlab::renderer::pathtraced;

namespace {
std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no InputError)";
}

std::string eeveeError(const std::string& override) {
    return errorOf([&] { loadSceneSpec("builtin:halo", {"sss.method=\"eevee\"", override}, {}); });
}
} // namespace

TEST(EeveeParams, DefaultsAndRecord) {
    const SceneSpec spec = loadSceneSpec("builtin:halo", {"sss.method=\"eevee\""}, {});
    const nlohmann::json& eevee = spec.resolved.at("eevee");
    EXPECT_EQ(eevee.at("sss_samples"), 7);            // Blender's default
    EXPECT_EQ(eevee.at("sss_jitter_threshold"), 0.3); // Blender's default
    EXPECT_EQ(eevee.at("taa_samples"), 16);
    EXPECT_EQ(eevee.at("sss"), true);
    const auto radius = eevee.at("radius_mm").get<std::array<double, 3>>();
    EXPECT_EQ(radius, fittedEeveeRadiusMm());
    // Other methods do not record the table (their images do not depend on it).
    EXPECT_FALSE(loadSceneSpec("builtin:halo", {}, {}).resolved.contains("eevee"));
    EXPECT_FALSE(loadSceneSpec("builtin:halo", {"sss.method=\"pathtraced\""}, {}).resolved.contains("eevee"));
    // Explicit values are kept, and the JSON form round-trips.
    const SceneSpec set = loadSceneSpec("builtin:halo",
                                        {"sss.method=\"eevee\"", "eevee.sss_samples=32", "eevee.taa_samples=4",
                                         "eevee.sss_jitter_threshold=0.0", "eevee.radius_mm=[2.0, 1.0, 0.0]"},
                                        {});
    const EeveeParams p = set.eevee;
    EXPECT_EQ(p.sssSamples, 32);
    EXPECT_EQ(p.taaSamples, 4);
    EXPECT_EQ(p.sssJitterThreshold, 0.0);
    EXPECT_EQ(p.radiusMm, (std::array<double, 3>{2.0, 1.0, 0.0}));
    EXPECT_EQ(eeveeParamsFromJson(p.toJson()).toJson(), p.toJson());
    // The settings every engine reads: the TAA samples stand where Cycles' samples do.
    EXPECT_EQ(p.sceneParams().samples, 4);
    EXPECT_EQ(p.sceneParams().radiusMm, p.radiusMm);
}

TEST(EeveeParams, BadValuesAreOneLineErrorsNamingTheKey) {
    EXPECT_EQ(eeveeError("eevee.sss_samples=0"), "builtin:halo: eevee.sss_samples: 0 is out of range [1, 32]");
    EXPECT_EQ(eeveeError("eevee.sss_samples=33"), "builtin:halo: eevee.sss_samples: 33 is out of range [1, 32]");
    EXPECT_EQ(eeveeError("eevee.sss_jitter_threshold=1.5"),
              "builtin:halo: eevee.sss_jitter_threshold: 1.5 is out of range [0, 1]");
    EXPECT_EQ(eeveeError("eevee.taa_samples=0"), "builtin:halo: eevee.taa_samples: 0 is out of range [1, 65536]");
    EXPECT_EQ(eeveeError("eevee.shadow_map_size=1000"),
              "builtin:halo: eevee.shadow_map_size: 1000 is not one of 512, 1024, 2048, 4096");
    EXPECT_EQ(eeveeError("eevee.specular_source=\"cycles\""),
              "builtin:halo: eevee.specular_source: 'cycles' is not one of \"eevee\", \"rasterizer\"");
    EXPECT_EQ(eeveeError("eevee.blender=\"\""),
              "builtin:halo: eevee.blender: must name the Blender program (e.g. \"blender\")");
    for (const std::string& bad : {std::string("eevee.radius_mm=[1.0, -1.0, 1.0]"), std::string("eevee.samples=4"),
                                   std::string("eevee.sss=2"), std::string("eevee.sss_samples=\"many\"")}) {
        const std::string message = eeveeError(bad);
        const std::string key = bad.substr(0, bad.find('='));
        EXPECT_NE(message.find(key), std::string::npos) << bad << " → " << message;
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
}

TEST(EeveeScene, EngineSettingsAndRadii) {
    const SceneSpec spec =
        loadSceneSpec("builtin:halo", {"sss.method=\"eevee\"", "sss.width_mm=6", "eevee.sss_samples=11"}, {});
    const Model model = makeHaloScene(static_cast<float>(spec.depthGapMm));
    const EeveeParams params = spec.eevee;
    BlenderSceneInputs inputs;
    inputs.spec = &spec;
    inputs.model = &model;
    for (const SubMesh& part : model.parts) {
        const MeshMaterial& m = model.materials[part.material];
        inputs.partMaterials.push_back({m.albedo, m.skin ? 1.0f : 0.0f, m.glossiness, m.specularIntensity});
    }
    inputs.camera = frameCamera(spec.camera, model.boundsMin, model.boundsMax, model.boundsMin, model.boundsMax,
                                spec.width, spec.height);
    inputs.params = params.sceneParams();
    inputs.sssWidthMm = spec.sss.widthMm;
    inputs.engine = "eevee";
    inputs.eeveeSettings = params.toJson();
    const nlohmann::json json = blenderSceneJson(inputs, "mesh.bin", "cycles.exr", "cycles.json");
    EXPECT_EQ(json.at("settings").at("engine"), "eevee");
    EXPECT_EQ(json.at("settings").at("samples"), 16); // TAA samples
    EXPECT_EQ(json.at("settings").at("eevee").at("sss_samples"), 11);
    EXPECT_GT(json.at("materials").at(0).at("specular").get<double>(), 0.0); // EEVEE's own specular lobe
    // specular_source = "rasterizer": no Principled specular (the renderer adds the rasterizer's specular pass).
    const EeveeParams borrowed =
        loadSceneSpec("builtin:halo", {"sss.method=\"eevee\"", "eevee.specular_source=\"rasterizer\""}, {}).eevee;
    inputs.params = borrowed.sceneParams();
    for (const auto& material : blenderSceneJson(inputs, "mesh.bin", "cycles.exr", "cycles.json").at("materials"))
        EXPECT_EQ(material.at("specular").get<double>(), 0.0);
    EXPECT_TRUE(json.at("world").at("shadow").get<bool>()); // one pass
    // Radii: the profile's mm at width 3 mm, scaled by width_mm / 3 (here 2), in scene units.
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(json.at("materials").at(0).at("radius").at(c).get<double>(),
                    fittedEeveeRadiusMm()[static_cast<std::size_t>(c)] * 2.0 / spec.mmPerUnit, 1e-9);
    // EEVEE's kernel has one radius per channel: no albedo table (pathtraced.radius_model is Cycles').
    EXPECT_EQ(params.sceneParams().radiusModel, "constant");
    for (const auto& material : json.at("materials")) EXPECT_FALSE(material.contains("radius_table"));
    inputs.params.radiusModel = "albedo";
    for (const auto& material : blenderSceneJson(inputs, "mesh.bin", "cycles.exr", "cycles.json").at("materials"))
        EXPECT_FALSE(material.contains("radius_table"));
}

TEST(EeveeProfile, EdgeResponseOfTheBurleyKernel) {
    // d = radius · 0.6 / (4π · 1.04) (Blender's compute_sss_kernel), the kernel ends at 16 d.
    EXPECT_NEAR(kEeveeBurleyDPerRadius, 0.045910, 1e-6);
    const double r = 2.0, end = 16.0 * kEeveeBurleyDPerRadius * r;
    EXPECT_NEAR(eeveeEdgeResponseAt(0.0, r), 0.5, 1e-12);
    EXPECT_EQ(eeveeEdgeResponseAt(end, r), 0.0);
    EXPECT_EQ(eeveeEdgeResponseAt(-end, r), 1.0);
    EXPECT_NEAR(eeveeEdgeResponseAt(0.3, r) + eeveeEdgeResponseAt(-0.3, r), 1.0, 1e-12); // symmetric kernel
    // Scale-free: E_r(x) = E_1(x / r).
    for (const double x : {0.01, 0.1, 0.5, 1.0})
        EXPECT_NEAR(eeveeEdgeResponseAt(x, r), eeveeEdgeResponseAt(x / r, 1.0), 1e-12);
    // Decreasing in x; against numerical integration of the kernel at one point (midpoint rule, 20000 cells).
    double previous = 0.5;
    for (double x = 0.01; x < end; x += 0.01) {
        const double e = eeveeEdgeResponseAt(x, r);
        EXPECT_LE(e, previous + 1e-15);
        previous = e;
    }
    const double d = kEeveeBurleyDPerRadius * r;
    auto kernel = [&](double t) { return std::exp(-std::abs(t) / d) + std::exp(-std::abs(t) / (3.0 * d)); };
    double all = 0.0, beyond = 0.0;
    const int cells = 20000;
    for (int i = 0; i < cells; ++i) {
        const double t = -end + (i + 0.5) * 2.0 * end / cells;
        all += kernel(t);
        if (t > 0.2) beyond += kernel(t);
    }
    EXPECT_NEAR(eeveeEdgeResponseAt(0.2, r), beyond / all, 2e-4); // the cell containing 0.2 straddles it
}

TEST(EeveeProfile, FittedRadiiMatchDeonsProfile) {
    const EdgeResponse response = eeveeEdgeResponse();
    const ProfileFit fit = fitRadii(response, {1.0, 1.0, 1.0});
    EXPECT_EQ(fit.radiusMm, fittedEeveeRadiusMm());
    for (int c = 0; c < 3; ++c) {
        std::printf("channel %d: radius %.4f mm, rms %.4f, max %.4f (radius 1 mm: rms %.4f)\n", c,
                    fit.radiusMm[static_cast<std::size_t>(c)], fit.rmsError[static_cast<std::size_t>(c)],
                    fit.maxError[static_cast<std::size_t>(c)], fit.initialRmsError[static_cast<std::size_t>(c)]);
        EXPECT_LT(fit.rmsError[static_cast<std::size_t>(c)], fit.initialRmsError[static_cast<std::size_t>(c)]);
        EXPECT_LT(fit.rmsError[static_cast<std::size_t>(c)], 0.03) << c;
    }
    // d'Eon's red lobes are the widest: red needs the largest radius, blue the smallest.
    EXPECT_GT(fit.radiusMm[0], fit.radiusMm[1]);
    EXPECT_GT(fit.radiusMm[1], fit.radiusMm[2]);
}
