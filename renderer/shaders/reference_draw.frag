#version 450 core
// Object-space reference, draw: a fragment counts only where it is the surface the main pass saw, i.e. where its
// view depth matches the main pass's linear depth (relative tolerance `depthTolerance`; the tessellated triangles
// lie in the planes of the main pass's triangles, so a match differs by rounding only). Of several matching
// fragments (the front and back faces meeting at a silhouette) the closest match wins: it is written as the
// fragment depth and tested LESS against a depth buffer of the draw's own. Where nothing matches (a non-skin
// occluder, the background) the output keeps the main pass's diffuse.
// Convolved = far field + own share × the main pass's diffuse E·α at this pixel (the near field at the pixel's
// resolution, not the tessellation's). Output = mask · convolved + (1 − mask) · main-pass diffuse, so partly skin
// pixels blend like the screen-space methods' output; alpha keeps the diffuse buffer's (the mask).
in vec3 scatteredFar;
in vec3 ownShare;
in float viewDepth;

layout(location = 0) out vec4 outColor;
layout(binding = 0) uniform sampler2D diffuse;      // main-pass diffuse (+ transmittance), a = mask
layout(binding = 1) uniform sampler2D mask;         // skin mask 0..1
layout(binding = 2) uniform sampler2D linearDepth;  // main pass, world units, +inf on background

uniform float depthTolerance;  // relative, e.g. 1e-4

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    float seen = texelFetch(linearDepth, pixel, 0).r;
    float allowed = depthTolerance * seen;
    float mismatch = abs(viewDepth - seen);
    if (!(mismatch <= allowed)) discard;  // also +inf (background) and NaN
    gl_FragDepth = mismatch / allowed * 0.5;  // in [0, 0.5]: the buffer is cleared to 1
    vec4 base = texelFetch(diffuse, pixel, 0);
    float m = clamp(texelFetch(mask, pixel, 0).r, 0.0, 1.0);
    vec3 scatteredDiffuse = scatteredFar + ownShare * base.rgb;
    outColor = vec4(mix(base.rgb, scatteredDiffuse, m), base.a);
}
