#include "renderer/sss/eevee_params.h"

#include "common/error.h"
#include "common/json_toml.h"
#include "common/spec.h"

namespace skinlab::renderer::pathtraced {

std::array<double, 3> fittedEeveeRadiusMm() {
    // fitRadii(eeveeEdgeResponse(), {1, 1, 1}).radiusMm (renderer/pathtraced/profile_fit.h), written with 17
    // significant digits so that the constants are the fit's doubles exactly.
    return {6.0724788147631816, 1.41155729915843, 0.93434684071438245};
}

namespace {
EeveeParams readTable(const SpecReader& t) {
    EeveeParams p;
    p.sssSamples = static_cast<int>(t.integer("sss_samples", p.sssSamples, 1, 32));
    p.sssJitterThreshold = t.number("sss_jitter_threshold", p.sssJitterThreshold, 0.0, 1.0);
    p.taaSamples = static_cast<int>(t.integer("taa_samples", p.taaSamples, 1, 1 << 16));
    p.sss = t.boolean("sss", p.sss);
    p.specular = t.boolean("specular", p.specular);
    p.specularSource = t.string("specular_source", p.specularSource);
    if (p.specularSource != "eevee" && p.specularSource != "rasterizer")
        t.fail("specular_source", "'" + p.specularSource + "' is not one of \"eevee\", \"rasterizer\"");
    p.radiusMm = t.vec3("radius_mm", p.radiusMm, 0.0, 1000.0);
    p.filterWidthPx = t.number("filter_width_px", p.filterWidthPx, 0.01, 10.0);
    p.shadowMapSize = static_cast<int>(t.integer("shadow_map_size", p.shadowMapSize, 512, 4096));
    if (p.shadowMapSize != 512 && p.shadowMapSize != 1024 && p.shadowMapSize != 2048 && p.shadowMapSize != 4096)
        t.fail("shadow_map_size", std::to_string(p.shadowMapSize) + " is not one of 512, 1024, 2048, 4096");
    p.softShadows = t.boolean("soft_shadows", p.softShadows);
    p.blender = t.string("blender", p.blender);
    if (p.blender.empty()) t.fail("blender", "must name the Blender program (e.g. \"blender\")");
    return p;
}
} // namespace

nlohmann::json EeveeParams::toJson() const {
    return {{"sss_samples", sssSamples},
            {"sss_jitter_threshold", sssJitterThreshold},
            {"taa_samples", taaSamples},
            {"sss", sss},
            {"specular", specular},
            {"specular_source", specularSource},
            {"radius_mm", radiusMm},
            {"filter_width_px", filterWidthPx},
            {"shadow_map_size", shadowMapSize},
            {"soft_shadows", softShadows},
            {"blender", blender}};
}

PathtracedParams EeveeParams::sceneParams() const {
    PathtracedParams p;
    p.samples = taaSamples;
    p.sss = sss;
    p.specular = specular;
    p.specularSource = specularSource == "rasterizer" ? "rasterizer" : "cycles"; // "rasterizer": Principled specular 0
    p.radiusMm = radiusMm;
    p.radiusModel = "constant"; // EEVEE's Burley kernel has its own fitted radii (one per channel)
    p.environmentShadow = true; // one pass: EEVEE's world light is unshadowed anyway (no ambient occlusion)
    p.sunAngleDeg = 0.0;
    p.filterWidthPx = filterWidthPx;
    p.blender = blender;
    return p;
}

EeveeParams readEeveeParams(const SpecReader& scene) {
    const SpecReader t = scene.table("eevee");
    EeveeParams p = readTable(t);
    t.finish();
    return p;
}

EeveeParams eeveeParamsFromJson(const nlohmann::json& json, std::string_view source) {
    return readEeveeParams(SpecReader(jsonAsTomlTable(json, source, "eevee"), std::string(source)));
}

} // namespace skinlab::renderer::pathtraced
