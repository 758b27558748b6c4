#version 450 core
#extension GL_GOOGLE_include_directive : require
// Transmittance pass (renderer/gl/transmittance_pass.h): the rgb added to the diffuse buffer by additive blending,
//   transmittance × (1 + c) with c = normalisedCurvature(curvature AOV) when transmittance.curvature is on with
//   curvature_form "scale", transmittance otherwise (the "thesis" form is applied inside the main pass).
// The main pass already applied exposure, albedo and the skin mask to the transmittance target.
#include "sss_extensions.glsl"

layout(location = 0) out vec4 outAdded;
layout(binding = 0) uniform sampler2D transmittance;  // rgb radiance (exposure applied), 0 off skin
layout(binding = 1) uniform sampler2D curvature;      // 1/world unit, >= 0
uniform int curvatureEnabled;
uniform float mmPerUnit;
uniform float curvatureReferenceMm;  // sss.curvature_reference_mm

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec3 transmitted = texelFetch(transmittance, pixel, 0).rgb;
    if (curvatureEnabled != 0) {
        float c = normalisedCurvature(texelFetch(curvature, pixel, 0).r, mmPerUnit, curvatureReferenceMm);
        transmitted *= transmittanceCurvatureScale(c);
    }
    outAdded = vec4(transmitted, 0.0);
}
