#include "renderer/sss/pathtraced_params.h"

#include "common/error.h"
#include "common/json_toml.h"
#include "common/spec.h"

#include <algorithm>

namespace skinlab::renderer::pathtraced {

std::array<double, 3> fittedRadiusMm() {
    // `skinlab pathtraced fit-profile` (defaults: 2048 × 8 pixels over ±4 mm at radius 1 mm, 256 samples, seed 0,
    // skin albedo (0.60, 0.42, 0.34); Blender 3.4.1).
    // rms error of the edge response over (0, 8] mm: 0.0068, 0.0036, 0.0050 (docs/pathtraced.md).
    return {8.663, 2.659, 1.998};
}

const AlbedoRadiusTable& albedoRadiusTable() {
    // `skinlab pathtraced fit-profile --samples 1024 --albedos 0.1,0.15,…,0.9` (grey slabs, 2048 × 8 pixels over
    // ±1.5 mm below albedo 0.25, ±2 mm below 0.55, ±3 mm above, at radius 1 mm; seed 0; Blender 3.4.1): the
    // per-albedo fits smoothed by a cubic in albedo through ln r (RMS residual 0.004, 0.007, 0.020 in R, G, B: the
    // fits' noise). docs/pathtraced.md, "Matched profiles". Below 0.10 (the darkest skin tones' channels): the raw
    // fits at 0.03, 0.05, 0.07 of the same sweep's settings (`--albedos 0.02,0.03,0.05,0.07,0.1`); at 0.02 the walk's
    // edge response equals that at 0.03 to 1e-7, so the table is constant below 0.03.
    static const AlbedoRadiusTable table{
        {0.03, 0.05, 0.07, 0.10, 0.15, 0.20, 0.25, 0.30, 0.35, 0.40,
         0.45, 0.50, 0.55, 0.60, 0.65, 0.70, 0.75, 0.80, 0.85, 0.90},
        {{{22.361,  22.150,  21.415, 20.0906, 18.2461, 16.6500, 15.2541, 14.0203, 12.9178, 11.9221,
           11.0131, 10.1748, 9.3945, 8.6619,  7.9692,  7.3104,  6.6813,  6.0790,  5.5022,  4.9503},
          {5.159,  5.157,  5.103,  4.6724, 4.2414, 3.8699, 3.5460, 3.2605, 3.0059, 2.7761,
           2.5664, 2.3728, 2.1924, 2.0225, 1.8615, 1.7078, 1.5605, 1.4191, 1.2832, 1.1528},
          {3.439,  3.413,  3.246,  3.0055, 2.7532, 2.5298, 2.3303, 2.1505, 1.9871, 1.8373,
           1.6989, 1.5701, 1.4493, 1.3355, 1.2278, 1.1253, 1.0278, 0.9348, 0.8461, 0.7618}}}};
    return table;
}

const WalkReflectanceTable& walkReflectanceTable() {
    // Cycles against the rasterizer on builtin:halo's backdrop 200 mm behind the sphere (a flat skin plane of grey
    // albedo a, pixels more than 40 px from the image centre), 128², seed 0, the agree settings, diffuse "lambert"
    // without the correction, the albedo radius model (Blender 3.4.1): Cycles / rasterizer, mean of R, G, B (which
    // agree within 0.15 %); 512 samples at 0.4 and from 0.6 on, 128 below. Not monotonic (a bump at 0.8–0.85,
    // measured twice), so every measured knot is kept. Below 0.05 the excess rises steeply (the darkest skin tones'
    // green and blue): the knots 0.01 … 0.04 are the gains g for which the walk given a / g reflects a, from the walk's
    // response measured at 64², 256 samples, seed 0 with the gain 1.0122 there (Cycles / rasterizer 1.0955, 1.0839,
    // 1.0703, 1.0425, 1.0155 at a = 0.01, 0.015, 0.02, 0.03, 0.04), inverted in log-log.
    static const WalkReflectanceTable table{
        {0.01, 0.015, 0.02, 0.03, 0.04, 0.05, 0.10, 0.20, 0.30, 0.40, 0.50, 0.60, 0.70, 0.75, 0.80, 0.85, 0.90},
        {1.1116, 1.0995, 1.0868, 1.0583, 1.0295, 1.0122, 1.0122, 1.0110, 1.0102, 1.0101, 1.0097, 1.0091, 1.0096, 1.0109,
         1.0124, 1.0123, 1.0057}};
    return table;
}

double tableRadiusMm(const AlbedoRadiusTable& table, int channel, double albedo) {
    const std::vector<double>& knots = table.albedo;
    const std::vector<double>& radius = table.radiusMm[static_cast<std::size_t>(channel)];
    if (!(albedo > knots.front())) return radius.front(); // NaN too
    if (albedo >= knots.back()) return radius.back();
    const auto upper = static_cast<std::size_t>(std::upper_bound(knots.begin(), knots.end(), albedo) - knots.begin());
    const double t = (albedo - knots[upper - 1]) / (knots[upper] - knots[upper - 1]);
    return radius[upper - 1] + t * (radius[upper] - radius[upper - 1]);
}

double radiusAtAlbedoMm(const PathtracedParams& params, int channel, double albedo) {
    const auto c = static_cast<std::size_t>(channel);
    if (params.radiusModel != "albedo") return params.radiusMm[c];
    const AlbedoRadiusTable& table = albedoRadiusTable();
    return params.radiusMm[c] * tableRadiusMm(table, channel, albedo) / tableRadiusMm(table, channel, kFitAlbedo[c]);
}

namespace {
PathtracedParams readTable(const SpecReader& t) {
    PathtracedParams p;
    p.samples = static_cast<int>(t.integer("samples", p.samples, 1, 1 << 20));
    p.seed = static_cast<int>(t.integer("seed", p.seed, 0, 2147483647));
    p.maxBounces = static_cast<int>(t.integer("max_bounces", p.maxBounces, 0, 1024));
    p.sss = t.boolean("sss", p.sss);
    p.specular = t.boolean("specular", p.specular);
    p.specularSource = t.string("specular_source", p.specularSource);
    if (p.specularSource != "cycles" && p.specularSource != "rasterizer")
        t.fail("specular_source", "'" + p.specularSource + "' is not one of \"cycles\", \"rasterizer\"");
    p.radiusMm = t.vec3("radius_mm", p.radiusMm, 1e-4, 1000.0);
    p.radiusModel = t.string("radius_model", p.radiusModel);
    if (p.radiusModel != "albedo" && p.radiusModel != "constant")
        t.fail("radius_model", "'" + p.radiusModel + "' is not one of \"albedo\", \"constant\"");
    p.diffuse = t.string("diffuse", p.diffuse);
    if (p.diffuse != "lambert" && p.diffuse != "principled")
        t.fail("diffuse", "'" + p.diffuse + "' is not one of \"lambert\", \"principled\"");
    p.environmentShadow = t.boolean("environment_shadow", p.environmentShadow);
    p.sunAngleDeg = t.number("sun_angle_deg", p.sunAngleDeg, 0.0, 90.0);
    p.filterWidthPx = t.number("filter_width_px", p.filterWidthPx, 0.01, 10.0);
    p.threads = static_cast<int>(t.integer("threads", p.threads, 0, 1024));
    p.blender = t.string("blender", p.blender);
    if (p.blender.empty()) t.fail("blender", "must name the Blender program (e.g. \"blender\")");
    return p;
}
} // namespace

nlohmann::json PathtracedParams::toJson() const {
    return {{"samples", samples},           {"seed", seed},
            {"max_bounces", maxBounces},    {"sss", sss},
            {"specular", specular},         {"specular_source", specularSource},
            {"radius_mm", radiusMm},        {"radius_model", radiusModel},
            {"diffuse", diffuse},           {"environment_shadow", environmentShadow},
            {"sun_angle_deg", sunAngleDeg}, {"filter_width_px", filterWidthPx},
            {"threads", threads},           {"blender", blender}};
}

PathtracedParams readPathtracedParams(const SpecReader& scene) {
    const SpecReader t = scene.table("pathtraced");
    PathtracedParams p = readTable(t);
    t.finish();
    return p;
}

PathtracedParams pathtracedParamsFromJson(const nlohmann::json& json, std::string_view source) {
    return readPathtracedParams(SpecReader(jsonAsTomlTable(json, source, "pathtraced"), std::string(source)));
}

} // namespace skinlab::renderer::pathtraced
