#version 450 core
#extension GL_GOOGLE_include_directive : require
// One 1-D pass of Mikkelsen's pseudo-separable cross-bilateral filter (method pscbf; M. S. Mikkelsen, "Skin
// Rendering by Pseudo-Separable Cross Bilateral Filtering", 2010; docs/extensions.md). The method
// runs it twice (renderer/gl/pscbf_method.cpp): horizontally on the diffuse buffer, then vertically on that result
// with PSCBF_FINAL_PASS, which adds the spike: output = spike · unblurred + (1 − spike) · blurred, per channel.
//
// Per skin pixel p (linear depth z, world units):
//   footprint   pixels per mm along the pass axis = f_px / (mm_per_unit · z) · c_axis · curvature width scale;
//               c_axis is Mikkelsen's tilt correction d' = d · cos φ_o, evaluated exactly for a perspective camera
//               (pscbfAxisScale below); the taps (mm on the surface, within ±r_max · width_mm / 3) come from
//               renderer/sss/pscbf_kernel.h;
//   texels      each tap falls between two texels along the axis (linear interpolation, done by hand so that each
//               texel is weighed on its own); a texel's weight is
//                   tap weight (RGB) × interpolation share × skin mask × depth weight (RGB) × extension weights
//               so non-skin texels are discarded (mask 0), not replaced by the centre colour;
//   depth       G(σ_c, Δ) = exp(−Δ² / (2 σ_c²)) per channel, Δ = the texel's linear depth minus the depth of the
//               centre's tangent plane along the texel's ray, in mm; σ_c = √v_c · width_mm / 3 (the profile's own
//               Gaussian: the 3-D Gaussian factorises, G(v, √(s² + Δ²)) = G(v, s) · exp(−Δ²/2v));
//   result      Σ w c / Σ w per channel, or the centre colour where Σ w < kMinimumWeightSum (resolveWeightedSum);
//               mix(centre, result, mask) on skin; non-skin pixels copied.
// Inputs: source rgb = colour (diffuse, or the horizontal pass's result), a = skin mask.

#include "sss_extensions.glsl"
#include "sss_extension_inputs.glsl"

#ifndef PSCBF_MAX_TAPS
#define PSCBF_MAX_TAPS 101  // sss.samples ≤ 101
#endif

layout(location = 0) out vec4 outColor;  // rgb = result, a = skin mask (carried to the next pass)

layout(binding = 0) uniform sampler2D source;           // rgb colour, a = skin mask
layout(binding = 1) uniform sampler2D linearDepth;      // r = view depth along −Z, world units, +inf on background
layout(binding = 2) uniform sampler2D geometricNormal;  // xyz = world-space geometric normal
layout(binding = 3) uniform sampler2D unblurred;        // PSCBF_FINAL_PASS: the diffuse buffer before both passes

uniform int horizontal;           // 1: along x, 0: along y
uniform float focalLengthPixels;  // f_px = (H/2) / tan(fovY/2)
uniform float mmPerUnit;          // millimetres per world unit
uniform vec2 principalPoint;      // image centre in pixels (W/2, H/2): the view axis
uniform mat3 worldToView;         // rotation part of the view matrix
uniform int hasGeometricNormal;   // 0: no normal texture; every pixel is taken to face the camera (c_axis = 1)
uniform int depthWeight;          // sss.follow_surface: 1 = depth range weight on
uniform vec3 depthSigmaMm;        // σ_c per channel, mm
uniform vec3 spike;               // share of the unblurred irradiance per channel (15/18/20 %)
uniform int tapCount;
uniform vec4 taps[PSCBF_MAX_TAPS];  // xyz = RGB weight (each channel sums to 1), w = offset in mm on the surface

// Smallest tilt factor: at silhouettes cos φ_o → 0 and the footprint would collapse to nothing (and the tangent
// plane's depth prediction diverges); 0.05 (φ_o ≈ 87°) keeps both finite and changes nothing at φ_o < 87°.
const float kPscbfMinAxisScale = 0.05;

// Tilt correction of the footprint along one screen axis (Mikkelsen: d' = d · cos φ_o, per axis). For a locally
// planar surface with view-space unit normal n seen along w = (ray to the camera at unit depth, w.z = 1), a step of
// one pixel along x moves the surface point by (z / f_px) · |e_x − n_x w / (n·w)|, so
//     c_x = |n·w| / √((n_y w_y + n_z)² + n_x² (1 + w_y²))          (c_y: swap x and y)
// On the view axis (w = (0, 0, 1)) this is n_z / √(n_x² + n_z²): cos φ_o measured in the XZ plane, exactly as
// Mikkelsen computes it; elsewhere it also accounts for the perspective (a plane facing the camera has c = 1 at
// every pixel, since f_px / z is exact for it).
float pscbfAxisScale(vec3 n, vec3 w) {
    float nw = abs(dot(n, w));
    float along = horizontal != 0 ? n.x : n.y;
    float across = horizontal != 0 ? n.y * w.y : n.x * w.x;
    float acrossRay = horizontal != 0 ? w.y : w.x;
    float denominator = sqrt((across + n.z) * (across + n.z) + along * along * (1.0 + acrossRay * acrossRay));
    return max(denominator > 0.0 ? nw / denominator : 1.0, kPscbfMinAxisScale);
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(source, 0);
    vec4 centreTexel = texelFetch(source, p, 0);
    vec3 centre = centreTexel.rgb;
    float centreMask = centreTexel.a;
    if (!(centreMask > 0.0)) {
        outColor = vec4(centre, centreMask);  // non-skin and background: copied
        return;
    }
    float centreDepth = texelFetch(linearDepth, p, 0).r;
    // Direction from the pixel's surface point to the camera, scaled to unit depth (view space, +Z towards the viewer).
    vec3 w = vec3((principalPoint - (vec2(p) + 0.5)) / focalLengthPixels, 1.0);
    vec3 n = vec3(0.0, 0.0, 1.0);
    if (hasGeometricNormal != 0) {
        vec3 normal = worldToView * texelFetch(geometricNormal, p, 0).xyz;
        if (dot(normal, normal) > 0.25) n = normalize(normal);  // 0 where the main pass wrote nothing
    }
    if (dot(n, w) < 0.0) n = -n;  // interpolated normals can turn slightly away at silhouettes
    float axisScale = hasGeometricNormal != 0 ? pscbfAxisScale(n, w) : 1.0;
    float pixelsPerMm = focalLengthPixels / (mmPerUnit * centreDepth) * axisScale * extensionWidthScale(p, mmPerUnit);

    // Depth of the centre's tangent plane along the ray of a texel `delta` pixels away on the pass axis:
    // z_plane = z · (n·w) / (n·w − n_axis · delta / f_px). Where the plane is seen edge-on (n·w small) the
    // prediction is meaningless and the plain depth difference is used (also for a texel whose ray would meet the
    // plane behind the camera or 20× farther away).
    float nw = dot(n, w);
    float nAxis = horizontal != 0 ? n.x : n.y;
    bool planePrediction = hasGeometricNormal != 0 && nw > kPscbfMinAxisScale;
    vec3 inverseTwoSigmaSquared = 1.0 / (2.0 * depthSigmaMm * depthSigmaMm);

#ifdef SSS_EXTENSION_WEIGHTS
    ExtensionCentre extension = extensionCentre(p);
#endif
    int along = horizontal != 0 ? p.x : p.y;
    int lastTexel = (horizontal != 0 ? size.x : size.y) - 1;
    vec3 sum = vec3(0.0);
    vec3 weightSum = vec3(0.0);
    for (int i = 0; i < tapCount; ++i) {
        float position = float(along) + taps[i].w * pixelsPerMm;
        float first = floor(position);
        float fraction = position - first;
        for (int t = 0; t < 2; ++t) {
            float share = t == 0 ? 1.0 - fraction : fraction;
            if (share <= 0.0) continue;
            int k = clamp(int(first) + t, 0, lastTexel);
            ivec2 q = horizontal != 0 ? ivec2(k, p.y) : ivec2(p.x, k);
            vec4 texel = texelFetch(source, q, 0);
            if (!(texel.a > 0.0)) continue;  // non-skin: discarded
            vec3 weight = taps[i].xyz * (share * texel.a);
            if (depthWeight != 0) {
                float expected = centreDepth;
                if (planePrediction) {
                    float denominator = nw - nAxis * float(k - along) / focalLengthPixels;
                    if (denominator > kPscbfMinAxisScale * nw) expected = centreDepth * nw / denominator;
                }
                float differenceMm = (texelFetch(linearDepth, q, 0).r - expected) * mmPerUnit;
                // +inf − finite = +inf → exp(−inf) = 0; guard the NaN of inf − inf (never on skin texels).
                weight *= isnan(differenceMm) ? vec3(0.0) : exp(-differenceMm * differenceMm * inverseTwoSigmaSquared);
            }
#ifdef SSS_EXTENSION_WEIGHTS
            weight *= extensionTexelWeight(extension, q);
#endif
            sum += weight * texel.rgb;
            weightSum += weight;
        }
    }
    vec3 blurred = resolveWeightedSumPerChannel(sum, weightSum, centre);
#ifdef PSCBF_FINAL_PASS
    vec3 original = texelFetch(unblurred, p, 0).rgb;
    vec3 result = mix(original, spike * original + (1.0 - spike) * blurred, centreMask);
#else
    vec3 result = mix(centre, blurred, centreMask);
#endif
    outColor = vec4(result, centreMask);
}
