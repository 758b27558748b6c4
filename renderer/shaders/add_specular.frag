#version 450 core
// Add specular (thesis pipeline): beauty = scattered diffuse + specular, after the SSS stage.
layout(location = 0) out vec4 outBeauty;
layout(binding = 0) uniform sampler2D scatteredDiffuse;
layout(binding = 1) uniform sampler2D specular;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    outBeauty = vec4(texelFetch(scatteredDiffuse, pixel, 0).rgb + texelFetch(specular, pixel, 0).rgb, 1.0);
}
