#pragma once
// Typed parameters of the scene spec table [eevee] (sss.method = "eevee": Blender EEVEE renders the scene with its
// screen-space subsurface scattering; docs/pathtraced.md, "EEVEE", lists every key with its unit and range), their
// strict reader and their JSON form. Beside pathtraced_params.h, below the scene reader and renderer/pathtraced.
#include "renderer/sss/pathtraced_params.h"

#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace skinlab {
class SpecReader;
}

namespace skinlab::renderer::pathtraced {

// Per-channel subsurface radii (mm) at sss.width_mm = 3 that make the edge response of EEVEE's Christensen–Burley
// kernel match d'Eon's sum of Gaussians: the result of fitRadii on eeveeEdgeResponse() (renderer/pathtraced/
// profile_fit.h) to the last bit, which the test EeveeProfile.FittedRadiiMatchDeonsProfile checks.
std::array<double, 3> fittedEeveeRadiusMm();

struct EeveeParams {
    // EEVEE's subsurface samples per direction (scene.eevee.sss_samples: the 1-D kernel has 2 n + 1 taps, applied
    // horizontally then vertically). Blender's default is 7; its range 1 … 32.
    int sssSamples = 7;
    // Kernel offsets (in [0, 1] of the kernel radius) below which a tap's direction is rotated at random per
    // pixel and per TAA sample instead of following the pass axis (scene.eevee.sss_jitter_threshold), [0, 1].
    double sssJitterThreshold = 0.3;
    // Temporal anti-aliasing samples accumulated per image (scene.eevee.taa_render_samples). With a pixel filter of
    // 0.01 px the camera is not jittered, so they average the SSS jitter and the shadow-map filtering only.
    int taaSamples = 16;
    bool sss = true;      // subsurface scattering on skin (false: Principled subsurface 0, a plain diffuse surface)
    bool specular = true; // the specular lobe (false: Principled specular 0)
    // Where the specular layer comes from: "eevee" (the Principled GGX lobe as EEVEE shades it) or "rasterizer"
    // (EEVEE renders no specular; the beauty is EEVEE's diffuse + the rasterizer's specular pass of the same camera),
    // so that the image differs from a screen-space render in the diffuse/subsurface layer only.
    std::string specularSource = "eevee";
    // Subsurface radius per channel (mm) at the profile's own scale; scaled by sss.width_mm / 3 and divided by
    // mm_per_unit like the path-traced radii. EEVEE's kernel reaches 16 d = 0.7346 × radius (d the Burley
    // parameter, below), so a radius of 0 turns the kernel into the centre tap.
    std::array<double, 3> radiusMm = fittedEeveeRadiusMm();
    double filterWidthPx = 0.01;     // render.filter_size; 0.01 point-samples the pixel centre like the rasterizer
    int shadowMapSize = 2048;        // shadow cascade (sun) and cube (spot) map size: 512, 1024, 2048 or 4096
    bool softShadows = false;        // EEVEE's soft shadows (false: hard shadows, as the rasterizer's shadow map)
    std::string blender = "blender"; // the Blender program (a name on PATH or a path)

    nlohmann::json toJson() const;
    // The settings blenderSceneJson reads for every engine (samples = TAA samples; one pass, no sun angle).
    PathtracedParams sceneParams() const;
};

// Reads the [eevee] table of a scene spec (read and finished here). Defaults for absent keys; InputError naming
// file and key for bad ones.
EeveeParams readEeveeParams(const SpecReader& scene);
// From the JSON form written by toJson(); same validation, errors name `source`.
EeveeParams eeveeParamsFromJson(const nlohmann::json& json, std::string_view source = "eevee");

} // namespace skinlab::renderer::pathtraced
