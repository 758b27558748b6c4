#version 450 core
// Shadow map: depth of the scene from one light (one layer of a depth texture array per shadow-casting light).
layout(location = 0) in vec3 position;  // world units

uniform mat4 lightViewProjection;

void main() {
    gl_Position = lightViewProjection * vec4(position, 1.0);
}
