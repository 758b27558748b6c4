#pragma once
// The reference method's own [sss] keys as its typed parameters (declared in reference.cpp), read by its executor
// (renderer/gl/reference_method.h).
#include "renderer/sss/sss_params.h"

#include <array>
#include <nlohmann/json.hpp>

namespace skinlab::renderer::sss {

// What becomes of the light the profile carries to non-skin neighbours (sss.reference_non_skin).
enum class ReferenceNonSkin {
    Returns, // handed back to the receiver, as the screen-space methods do: skin is judged as if nothing bordered it
    Absorbs, // it leaves the skin, as a path tracer's walk ends where the skin's medium ends (the validation's setting)
};
NLOHMANN_JSON_SERIALIZE_ENUM(ReferenceNonSkin,
                             {{ReferenceNonSkin::Returns, "returns"}, {ReferenceNonSkin::Absorbs, "absorbs"}})

// Where the near field is drawn (sss.reference_near_field).
enum class ReferenceNearField {
    // every source's light, the receiver's own included, summed at the vertices and interpolated across the
    // triangles: detail finer than the edge length is lost
    Vertex,
    // the receiver's own term and sources closer than half the edge length, the profile's narrow lobes, multiply the
    // main pass's E·α at every pixel: a sharp light edge or pore keeps the sharpness those lobes give it instead of a
    // staircase of the tessellation
    Pixel,
};
NLOHMANN_JSON_SERIALIZE_ENUM(ReferenceNearField,
                             {{ReferenceNearField::Vertex, "vertex"}, {ReferenceNearField::Pixel, "pixel"}})

// renderer/reference/surface_convolution.h describes each; the defaults are the keys' defaults.
struct ReferenceParams {
    // Longest skin edge (mm) after tessellation; irradiance is sampled at the vertices (sss.reference_edge_mm).
    double edgeMm = 1.0;
    // The light that reaches a receiver from the far side of a thin part (sources whose normal faces away from the
    // receiver's) is the reflectance profile at the 3-D distance d through the part times a per-channel gain
    // g_c · exp(k_c d²): throughGain holds g_c (sss.reference_through_gain), throughGrowthPerMm2 k_c
    // (sss.reference_through_growth_per_mm2; 1/mm² at width_mm = 3, scaled by profileScale⁻² with the profile, so
    // the factor widens each Gaussian lobe of variance v to v / (1 − 2 k_c v) at every width). g = 1, k = 0: the
    // profile as it is; k = 0: a constant gain. Defaults: fitted to Blender Cycles' random walk on 1, 2, 2.5 and
    // 4 mm skin fins (scripts/transmittance-calibration.sh; docs/pathtraced.md, "Through-light: calibration").
    std::array<double, 3> throughGain{1.181, 5.727, 9.723};
    std::array<double, 3> throughGrowthPerMm2{0.04, -0.04, 0.0};
    ReferenceNonSkin nonSkin = ReferenceNonSkin::Returns;
    // Per-channel length L_c (mm at width_mm = 3, scaled with the profile) of the convex-surface gain 1 + L_c κ (κ the
    // curvature the kernel sees, 1/mm; sss.reference_convexity_mm). 0 (the default): a level-neutral reference, as
    // every screen-space method is; the fit to the path tracer's level on a sphere is in docs/pathtraced.md,
    // "A convex body's level".
    std::array<double, 3> convexityMm{0.0, 0.0, 0.0};
    ReferenceNearField nearField = ReferenceNearField::Vertex;
};

// The reference keys of `params` (the defaults above for a parameter set of another method).
ReferenceParams referenceParams(const SssParams& params);

} // namespace skinlab::renderer::sss
