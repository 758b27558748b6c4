#version 450 core
#extension GL_GOOGLE_include_directive : require
// One 1-D screen-space subsurface-scattering pass (horizontal or vertical) with a tabulated kernel: the pass of the
// separable and artistic methods (two passes) and of the gaussian-sum method (12 passes, SSS_ACCUMULATE on the
// vertical ones). Mirrors renderer/sss/cpu_blur.cpp operation for operation (docs/methods.md):
//   pixels per mm = f_px / (mm_per_unit · z_centre), the same on both axes (docs/methods.md), × the curvature width
//   scale of sss.curvature (E3; exactly 1 when off);
//   each tap linearly interpolates the two texels it falls between, each texel first replaced by the centre colour
//   in proportion to its non-skin share (1 − mask) and, with follow-surface, saturate(k · |Δz| · mm_per_unit);
//   skin pixels get mix(centre, Σ w·tap, mask); non-skin pixels are copied.
// With SSS_EXTENSION_WEIGHTS (sss.cbf and/or sss.lab_weight on; docs/extensions.md) each of the two texels of a tap
// weighs w_i · (its interpolation share) · labWeight · auxiliaryWeight, and the sum is renormalised per channel by
// the summed weights, falling back to the centre where they vanish.
// Inputs: source rgb = linear diffuse colour, a = skin mask; linearDepth r = view depth in world units (+inf on
// background); the extension textures of sss_extension_inputs.glsl.
#include "sss_extensions.glsl"
#include "sss_extension_inputs.glsl"

#ifndef SSS_MAX_TAPS
#define SSS_MAX_TAPS 101  // sss.samples ≤ 101
#endif

layout(location = 0) out vec4 outColor;  // rgb = this pass's result, a = skin mask (carried to the next pass)
#ifdef SSS_ACCUMULATE
layout(location = 1) out vec4 outAccumulated;  // rgb = accumulateWeight · result, added by GL_ONE, GL_ONE blending
#endif

layout(binding = 0) uniform sampler2D source;
layout(binding = 1) uniform sampler2D linearDepth;

uniform int horizontal;          // 1: along x, 0: along y
uniform float focalLengthPixels; // f_px = (H/2) / tan(fovY/2)
uniform float mmPerUnit;         // millimetres per world unit
uniform int followSurface;       // 0 or 1
uniform float followSurfaceK;    // 1/mm
uniform int tapCount;
uniform vec4 taps[SSS_MAX_TAPS]; // xyz = RGB weight, w = offset in mm on the surface
uniform vec3 accumulateWeight;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(source, 0);
    vec4 centreTexel = texelFetch(source, p, 0);
    vec3 centre = centreTexel.rgb;
    float centreMask = centreTexel.a;
    vec3 result = centre;
    if (centreMask > 0.0) {
        float centreDepth = texelFetch(linearDepth, p, 0).r;
        float pixelsPerMm = focalLengthPixels / (mmPerUnit * centreDepth);
        if (extensionCurvatureStrategy != kCurvatureOff) pixelsPerMm *= extensionWidthScale(p, mmPerUnit);
        int along = horizontal != 0 ? p.x : p.y;
        int lastTexel = (horizontal != 0 ? size.x : size.y) - 1;
        vec3 sum = vec3(0.0);
#ifdef SSS_EXTENSION_WEIGHTS
        ExtensionCentre extension = extensionCentre(p);
        vec3 weightSum = vec3(0.0);
        float texelWeights[2];
#endif
        for (int i = 0; i < tapCount; ++i) {
            float position = float(along) + taps[i].w * pixelsPerMm;
            float first = floor(position);
            float fraction = position - first;
            int j = int(first);
            vec3 values[2];
            for (int t = 0; t < 2; ++t) {
                int k = clamp(j + t, 0, lastTexel);
                ivec2 q = horizontal != 0 ? ivec2(k, p.y) : ivec2(p.x, k);
                vec4 texel = texelFetch(source, q, 0);
                float s = 1.0 - texel.a;
                if (followSurface != 0 && texel.a > 0.0)
                    s = max(s, clamp(followSurfaceK * abs(centreDepth - texelFetch(linearDepth, q, 0).r) * mmPerUnit,
                                     0.0, 1.0));
                values[t] = mix(texel.rgb, centre, s);
#ifdef SSS_EXTENSION_WEIGHTS
                texelWeights[t] = extensionTexelWeight(extension, q);
#endif
            }
#ifdef SSS_EXTENSION_WEIGHTS
            vec3 weight0 = taps[i].xyz * ((1.0 - fraction) * texelWeights[0]);
            vec3 weight1 = taps[i].xyz * (fraction * texelWeights[1]);
            sum += weight0 * values[0] + weight1 * values[1];
            weightSum += weight0 + weight1;
#else
            sum += taps[i].xyz * mix(values[0], values[1], fraction);
#endif
        }
#ifdef SSS_EXTENSION_WEIGHTS
        sum = resolveWeightedSumPerChannel(sum, weightSum, centre);
#endif
        result = mix(centre, sum, centreMask);
    }
    outColor = vec4(result, centreMask);
#ifdef SSS_ACCUMULATE
    outAccumulated = vec4(accumulateWeight * result, centreMask);
#endif
}
