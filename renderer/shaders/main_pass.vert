#version 450 core
// Main pass: transforms the model (already in world units) and hands the surface attributes to main_pass.frag.
layout(location = 0) in vec3 position;   // world units
layout(location = 1) in vec3 normal;     // unit, world space
layout(location = 2) in vec2 uv;         // v = 0 at the top of texture images
layout(location = 3) in vec4 tangent;    // xyz unit tangent, w = bitangent handedness
layout(location = 4) in vec3 color;      // linear albedo multiplier
layout(location = 5) in float skin;      // skin mask multiplier 0..1

uniform mat4 view;
uniform mat4 projection;

out vec3 worldPosition;
out vec3 worldNormal;
out vec4 worldTangent;
out vec2 textureCoordinate;
out vec3 vertexColor;
out float vertexSkin;

void main() {
    worldPosition = position;
    worldNormal = normal;
    worldTangent = tangent;
    textureCoordinate = uv;
    vertexColor = color;
    vertexSkin = skin;
    gl_Position = projection * view * vec4(position, 1.0);
}
