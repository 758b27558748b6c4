#version 450 core
// Surface-AOV pass, second half (renderer/gl/surface_aov_pass.h): the raw curvature smoothed on skin by a truncated
// Gaussian of standard deviation SIGMA_PIXELS over (2 radius + 1) taps, run twice: along x (`direction` (1, 0)),
// then along y over the result (`direction` (0, 1)), each pass averaging only the taps that were measured (>= 0)
// and lie on the same surface as the centre (|depth difference| <= depthStepPixels pixel footprints per pixel of
// offset), so curvature does not leak across silhouettes or onto non-skin.
// Source and first-pass output carry (curvature, linear depth) so that each tap is one fetch; curvature -1 marks a
// skin pixel where nothing was measured, -2 a pixel off skin. The second pass writes the curvature AOV: 0 for both.
#define SIGMA_PIXELS 1.5

layout(location = 0) out vec2 outCurvature;  // (1/world unit, world units); the final pass writes .x only

layout(binding = 0) uniform sampler2D source;  // (curvature 1/world unit or -1 / -2, linear depth world units)
uniform vec2 direction;          // (1, 0) or (0, 1)
// 3. A uniform, not a constant, so the loop is not unrolled: Mesa's llvmpipe runs a loop only while one of its
// pixels is active, whereas unrolled code runs for off-skin pixels too.
uniform int radius;
uniform int finalPass;           // 1: write the AOV (0 where nothing was measured and off skin)
uniform float focalLengthPixels;
uniform float depthStepPixels;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec2 centre = texelFetch(source, pixel, 0).rg;
    if (centre.x <= -2.0) {
        outCurvature = vec2(finalPass != 0 ? 0.0 : -2.0, centre.y);
        return;
    }
    float depth = centre.y;
    ivec2 size = textureSize(source, 0);
    ivec2 step = ivec2(direction);
    float stepThreshold = depthStepPixels * depth / focalLengthPixels;  // world units per pixel of offset
    float sum = 0.0;
    float weightSum = 0.0;
    for (int i = -radius; i <= radius; ++i) {
        vec2 tap = texelFetch(source, clamp(pixel + i * step, ivec2(0), size - ivec2(1)), 0).rg;
        if (tap.x >= 0.0 && abs(tap.y - depth) <= stepThreshold * float(abs(i))) {
            float weight = exp(-float(i * i) / (2.0 * SIGMA_PIXELS * SIGMA_PIXELS));
            sum += weight * tap.x;
            weightSum += weight;
        }
    }
    float unmeasured = finalPass != 0 ? 0.0 : -1.0;
    outCurvature = vec2(weightSum > 0.0 ? sum / weightSum : unmeasured, depth);
}
