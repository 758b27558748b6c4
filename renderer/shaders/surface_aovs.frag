#version 450 core
#extension GL_GOOGLE_include_directive : require
// Surface-AOV pass, first half (renderer/gl/surface_aov_pass.h): per skin pixel
//   aux       = auxiliaryValue(view position, view-space geometric normal, albedo grey)  (sss_extensions.glsl)
//   curvature = max(0, mean over the x and y axes of dot(N(p+1) - N(p-1), P(p+1) - P(p-1)) / |P(p+1) - P(p-1)|^2)
// with P the view-space position (world units) and N the view-space geometric normal: the signed normal curvature
// along each screen axis (convex > 0; a sphere of radius r gives 1/r exactly, a plane 0). Central differences
// where both neighbours lie on the same skin surface, one-sided where only one does; a neighbour off skin, on the
// background or across a depth step (|depth difference| > depthStepPixels pixel footprints) is rejected. Where
// neither axis has a neighbour the curvature is -1 (unmeasured; the smoothing skips it). Off skin: aux 0,
// curvature -2. The curvature output carries the linear depth beside it for the smoothing (curvature_smooth.frag).
// With screenCurvature = 1 (sss.curvature_measure = "screen") the curvature is instead the thesis' screen-space
// measure (its §3.3.3 and main-pass shader), from the per-pixel change of the view-space geometric normal
// (dx, dy: central differences of the same-surface neighbours, one-sided where only one is usable, standing in for
// dFdx / dFdy): (cross(n − dx, n + dx).y − cross(n − dy, n + dy).x) · 2 / distance to the camera, clamped ≥ 0, then
// × f_px / 8 so that a sphere of radius r seen face-on reads 1/r at its centre, like the 3-D measure. It grows
// towards silhouettes, where the normal turns fast per pixel.
#include "sss_extensions.glsl"

layout(location = 0) out float outAux;
layout(location = 1) out vec2 outCurvature;  // (1/world unit or -1 / -2, linear depth in world units)

layout(binding = 0) uniform sampler2D linearDepth;      // world units along the view axis, +inf on background
layout(binding = 1) uniform sampler2D geometricNormal;  // world space, unit
layout(binding = 2) uniform sampler2D albedo;           // linear
layout(binding = 3) uniform sampler2D skinMask;         // 0..1
uniform vec4 ndcToView;          // (1/P00, 1/P11, P20/P00, P21/P11) of the perspective projection P (column-major)
uniform mat3 viewFromWorld;      // rotation part of the view matrix
uniform vec2 viewportSize;       // pixels
uniform float focalLengthPixels; // (H/2) / tan(fovY/2)
uniform float depthStepPixels;   // depth-step threshold in pixel footprints
// 2 (x and y). A uniform, not a constant, so the loop over the axes is not unrolled: Mesa's llvmpipe runs a loop
// only while one of its pixels is active, whereas unrolled code runs for background pixels too (the pass then
// costs 3× more on the CPU; measured, docs/benchmarks.md).
uniform int axisCount;
uniform int screenCurvature;     // 0: 3-D normal curvature; 1: the thesis' screen-space measure

// View-space position of the surface seen through the centre of `pixel` at linear depth `depth` (view z = -depth):
// a perspective projection maps x to ndc.x = (P00 x + P20 z) / -z, so x = depth (ndc.x / P00 + P20 / P00).
vec3 viewPositionAt(ivec2 pixel, float depth) {
    vec2 ndc = (vec2(pixel) + 0.5) / viewportSize * 2.0 - 1.0;
    return vec3((ndc * ndcToView.xy + ndcToView.zw) * depth, -depth);
}

// True (with its position and normal) when `pixel` is a skin pixel on the same surface as a centre at `centreDepth`.
bool sameSurface(ivec2 pixel, float centreDepth, out vec3 position, out vec3 normal) {
    position = vec3(0.0);
    normal = vec3(0.0);
    if (any(lessThan(pixel, ivec2(0))) || any(greaterThanEqual(pixel, ivec2(viewportSize)))) return false;
    if (texelFetch(skinMask, pixel, 0).r <= 0.0) return false;
    float depth = texelFetch(linearDepth, pixel, 0).r;
    if (isinf(depth) || abs(depth - centreDepth) > depthStepPixels * centreDepth / focalLengthPixels) return false;
    position = viewPositionAt(pixel, depth);
    normal = viewFromWorld * texelFetch(geometricNormal, pixel, 0).xyz;
    return true;
}

// Normal curvature along one screen axis; false where neither neighbour is usable.
bool axisCurvature(ivec2 pixel, ivec2 step, float depth, vec3 position, vec3 normal, out float curvature) {
    curvature = 0.0;
    vec3 plusPosition, plusNormal, minusPosition, minusNormal;
    bool plus = sameSurface(pixel + step, depth, plusPosition, plusNormal);
    bool minus = sameSurface(pixel - step, depth, minusPosition, minusNormal);
    if (!plus && !minus) return false;
    if (!plus) {
        plusPosition = position;
        plusNormal = normal;
    }
    if (!minus) {
        minusPosition = position;
        minusNormal = normal;
    }
    vec3 positionDifference = plusPosition - minusPosition;
    float length2 = dot(positionDifference, positionDifference);
    if (!(length2 > 0.0)) return false;
    curvature = dot(plusNormal - minusNormal, positionDifference) / length2;
    return true;
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    float mask = texelFetch(skinMask, pixel, 0).r;
    float depth = texelFetch(linearDepth, pixel, 0).r;
    if (mask <= 0.0 || isinf(depth)) {
        outAux = 0.0;
        outCurvature = vec2(-2.0, depth);
        return;
    }
    vec3 position = viewPositionAt(pixel, depth);
    vec3 normal = normalize(viewFromWorld * texelFetch(geometricNormal, pixel, 0).xyz);
    vec3 rgb = texelFetch(albedo, pixel, 0).rgb;
    outAux = auxiliaryValue(position, normal, (rgb.r + rgb.g + rgb.b) / 3.0);

    if (screenCurvature != 0) {
        vec3 dn[2];
        bool measuredAxis[2];
        for (int axis = 0; axis < 2; ++axis) {
            ivec2 step = axis == 0 ? ivec2(1, 0) : ivec2(0, 1);
            vec3 plusPosition, plusNormal, minusPosition, minusNormal;
            bool plus = sameSurface(pixel + step, depth, plusPosition, plusNormal);
            bool minus = sameSurface(pixel - step, depth, minusPosition, minusNormal);
            measuredAxis[axis] = plus || minus;
            if (plus && minus) dn[axis] = 0.5 * (normalize(plusNormal) - normalize(minusNormal));
            else if (plus) dn[axis] = normalize(plusNormal) - normal;
            else if (minus) dn[axis] = normal - normalize(minusNormal);
            else dn[axis] = vec3(0.0);
        }
        if (!measuredAxis[0] && !measuredAxis[1]) {
            outCurvature = vec2(-1.0, depth);
            return;
        }
        float thesis = (cross(normal - dn[0], normal + dn[0]).y - cross(normal - dn[1], normal + dn[1]).x) * 2.0 /
                       length(position);
        outCurvature = vec2(max(thesis, 0.0) * focalLengthPixels / 8.0, depth);
        return;
    }

    // Mean over the axes that could be measured, clamped at 0; -1 where none could.
    float sum = 0.0;
    int measured = 0;
    for (int axis = 0; axis < axisCount; ++axis) {
        float axisValue;
        if (axisCurvature(pixel, axis == 0 ? ivec2(1, 0) : ivec2(0, 1), depth, position, normal, axisValue)) {
            sum += axisValue;
            ++measured;
        }
    }
    outCurvature = vec2(measured > 0 ? max(sum / float(measured), 0.0) : -1.0, depth);
}
