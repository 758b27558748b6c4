#pragma once
// Typed parameters of the scene spec table [pathtraced] (sss.method = "pathtraced": Blender Cycles renders the
// scene; docs/pathtraced.md lists every key with its unit and range), their strict reader and their JSON form.
// They live in renderer/sss beside the [sss] table, below both the scene reader (renderer/scene) and the Blender
// writer (renderer/pathtraced), which both include them; the namespace is the feature's.
#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace skinlab {
class SpecReader;
}

namespace skinlab::renderer::pathtraced {

// Per-channel random-walk radii (mean free paths, mm) at sss.width_mm = 3, fitted so that the radial profile of
// Cycles' RANDOM_WALK_FIXED_RADIUS on a flat skin slab matches d'Eon's sum of Gaussians (the profile of the
// screen-space methods): `skinlab pathtraced fit-profile`, docs/pathtraced.md "Matched profiles".
// The values and the measurement that produced them: pathtraced_params.cpp.
std::array<double, 3> fittedRadiusMm();

// The subsurface colour the single-albedo fit above was made at (the built-in scenes' skin).
inline constexpr std::array<double, 3> kFitAlbedo{0.60, 0.42, 0.34};

// A random walk's profile width depends on the albedo at a fixed radius, d'Eon's profile does not: the radius that
// matches d'Eon per channel as a function of the subsurface colour a of that channel (grey slabs, one render per
// albedo: `skinlab pathtraced fit-profile --albedos`, docs/pathtraced.md "Matched profiles"). Piecewise linear in a
// between the knots, constant beyond the first and the last. Values: pathtraced_params.cpp.
struct AlbedoRadiusTable {
    std::vector<double> albedo;                  // knots, ascending
    std::array<std::vector<double>, 3> radiusMm; // per channel, one per knot (mm at sss.width_mm = 3)
};
const AlbedoRadiusTable& albedoRadiusTable();
double tableRadiusMm(const AlbedoRadiusTable& table, int channel, double albedo);

// Cycles' fixed-radius random walk reflects a little more than its colour asks: a flat, uniformly lit skin surface of
// colour a returns k(a)·a (k ≈ 1.09 at a = 0.02, 1.012 at 0.05 … 0.1, 1.006 at 0.9; the same in every channel, the
// walk being scale-free). With pathtraced.diffuse = "lambert" the walk is given a / g(a) per channel, g ≈ k, so that
// flat skin reflects exactly its colour, as the rasterizer's Lambertian does. Piecewise linear in a, constant beyond
// the ends. Values and their
// measurement: pathtraced_params.cpp; docs/pathtraced.md, "Flat skin reflects its colour".
struct WalkReflectanceTable {
    std::vector<double> albedo; // knots, ascending
    std::vector<double> gain;   // k at each knot
};
const WalkReflectanceTable& walkReflectanceTable();

struct PathtracedParams {
    int samples = 64;     // camera samples per pixel (no adaptive sampling, no denoising)
    int seed = 0;         // Cycles' sampling seed
    int maxBounces = 8;   // total, diffuse and glossy bounce limits (0: direct light only)
    bool sss = true;      // random-walk subsurface scattering on skin (false: a plain Principled surface)
    bool specular = true; // the specular lobe (false: Principled specular 0)
    // Where the specular layer comes from: "cycles" (Cycles' GGX lobe, environment reflections included) or
    // "rasterizer" (Cycles renders no specular; the beauty is Cycles' diffuse + the rasterizer's specular pass of
    // the same camera), so that a reference differs from a screen-space render in the subsurface transport only.
    std::string specularSource = "cycles";
    // Random-walk radii per channel (mm) at the profile's own scale; scaled by sss.width_mm / 3 like every
    // screen-space kernel, then divided by mm_per_unit (Cycles takes them in scene units). With radiusModel
    // "albedo" it is the radius at the built-in skin's colour kFitAlbedo (radiusAtAlbedoMm).
    std::array<double, 3> radiusMm = fittedRadiusMm();
    // "albedo": the radius of each channel follows the subsurface colour per texel through albedoRadiusTable()
    // (Cycles evaluates the table in the shader); "constant": radiusMm everywhere, whatever the colour.
    std::string radiusModel = "albedo";
    // The diffuse model of Cycles' surfaces: "lambert" (a Lambertian Diffuse BSDF off skin, the Subsurface
    // Scattering node's random walk with Lambertian entry and exit on skin: the rasterizer's model) or "principled"
    // (the Principled BSDF's Burley diffuse and its subsurface, whose retro-reflection lobe brightens grazing views).
    std::string diffuse = "lambert";
    // false: the environment lights every point as if nothing occluded it (objects cast no shadow on its light;
    // lights keep theirs), as the rasterizer's SH ambient term does: Cycles then renders the lights and the
    // environment in two passes and sums them. true: the environment is shadowed like any light.
    bool environmentShadow = true;
    double sunAngleDeg = 0.0;        // angular diameter of directional lights (0: a hard sun, as the shadow map)
    double filterWidthPx = 0.01;     // pixel filter width; 0.01 point-samples the pixel centre like the rasterizer
    int threads = 0;                 // Cycles threads (0: all cores); pixels do not depend on it
    std::string blender = "blender"; // the Blender program (a name on PATH or a path)

    nlohmann::json toJson() const;
};

// The radius (mm at sss.width_mm = 3) of channel c where the subsurface colour of that channel is `albedo`:
// "constant": radiusMm[c]; "albedo": radiusMm[c] · T_c(albedo) / T_c(kFitAlbedo[c]) with T = albedoRadiusTable(),
// so radius_mm is the radius at the built-in skin's colour and a per-channel multiplier of the table elsewhere.
double radiusAtAlbedoMm(const PathtracedParams& params, int channel, double albedo);

// Reads the [pathtraced] table of a scene spec (read and finished here). Defaults for absent keys; InputError
// naming file and key for bad ones.
PathtracedParams readPathtracedParams(const SpecReader& scene);
// From the JSON form written by toJson(); same validation, errors name `source`.
PathtracedParams pathtracedParamsFromJson(const nlohmann::json& json, std::string_view source = "pathtraced");

} // namespace skinlab::renderer::pathtraced
