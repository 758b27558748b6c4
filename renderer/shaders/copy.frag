#version 450 core
// Copies a texture through unchanged (SSS method "none").
layout(location = 0) out vec4 outColor;
layout(binding = 0) uniform sampler2D source;

void main() {
    outColor = texelFetch(source, ivec2(gl_FragCoord.xy), 0);
}
