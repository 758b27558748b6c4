#version 450 core
// Resolve (supersampling anti-aliasing): one output pixel from the factor × factor internal samples it covers
// (render.antialiasing = "ssaa", docs/rendering.md, "Anti-aliasing"). The reconstruction filter is a box of one
// output pixel: every sample of the pixel weighs 1 / factor², none of a neighbour's, the same footprint as
// Blender Cycles' box pixel filter (width 1 px). Values are linear (scene-referred); the tone map follows on the
// resolved beauty.
//   mode 0, average:            mean of all samples (radiometric layers, albedo, transmittance; the mask becomes
//                               the pixel's skin coverage);
//   mode 1, covered average:    mean over the samples that see a surface (finite linear depth); 0 where none do
//                               (aux, curvature: quantities of the surface, not of the pixel);
//   mode 2, covered direction:  as 1, renormalised to unit length (normals);
//   mode 3, nearest:            the smallest value (linear depth: the nearest surface any sample sees, +inf where
//                               none does).
layout(location = 0) out vec4 outResolved;
layout(binding = 0) uniform sampler2D source;      // internal resolution: output size × factor
layout(binding = 1) uniform sampler2D linearDepth; // internal resolution, world units, +inf on background
uniform int factor;
uniform int mode;

void main() {
    ivec2 first = ivec2(gl_FragCoord.xy) * factor;
    vec4 sum = vec4(0.0);
    float covered = 0.0;
    float nearest = uintBitsToFloat(0x7F800000u); // +inf
    for (int y = 0; y < factor; ++y) {
        for (int x = 0; x < factor; ++x) {
            ivec2 texel = first + ivec2(x, y);
            vec4 value = texelFetch(source, texel, 0);
            if (mode == 3) {
                nearest = min(nearest, value.r);
            } else if (mode == 0) {
                sum += value;
            } else if (!isinf(texelFetch(linearDepth, texel, 0).r)) {
                sum += value;
                covered += 1.0;
            }
        }
    }
    if (mode == 3) {
        outResolved = vec4(nearest, 0.0, 0.0, 0.0);
    } else if (mode == 0) {
        outResolved = sum / float(factor * factor);
    } else if (covered == 0.0) {
        outResolved = vec4(0.0);
    } else if (mode == 1) {
        outResolved = sum / covered;
    } else {
        vec3 direction = sum.xyz / covered;
        float size = length(direction);
        outResolved = vec4(size > 0.0 ? direction / size : vec3(0.0), sum.w / covered);
    }
}
