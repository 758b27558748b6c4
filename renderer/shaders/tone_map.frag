#version 450 core
#extension GL_GOOGLE_include_directive : require
// Tone map: beauty (linear, exposure applied in the main pass) → display-referred linear [0, 1]. The sRGB
// encoding is applied afterwards through OpenColorIO (renderer/output/display_transform.h).
#include "tone_mappers.glsl"

layout(location = 0) out vec4 outDisplay;
layout(binding = 0) uniform sampler2D beauty;
uniform int operatorIndex;
uniform float exponentialK;
uniform float filmicWhite;
uniform float reinhardScale;  // a / L̄ (Reinhard et al. 2002, Eq. 2)

void main() {
    vec3 x = texelFetch(beauty, ivec2(gl_FragCoord.xy), 0).rgb;
    outDisplay = vec4(toneMap(x, operatorIndex, exponentialK, filmicWhite, reinhardScale), 1.0);
}
