#version 450 core
// Object-space reference, draw (renderer/gl/reference_method.h): the tessellated skin parts with the camera of the
// main pass; each vertex carries its convolved diffuse radiance from a storage buffer indexed by the vertex index
// (gl_VertexID of an indexed draw), interpolated across the triangle.
layout(location = 0) in vec3 position;  // world units

layout(std430, binding = 0) readonly buffer ConvolvedDiffuse {
    vec4 convolved[];  // rgb: diffuse radiance after SSS (exposure applied), per vertex
};

uniform mat4 view;
uniform mat4 projection;

out vec3 scatteredDiffuse;
out float viewDepth;  // world units along the view axis, as the main pass's linear depth AOV

void main() {
    scatteredDiffuse = convolved[gl_VertexID].rgb;
    vec4 viewPosition = view * vec4(position, 1.0);
    viewDepth = -viewPosition.z;
    gl_Position = projection * viewPosition;
}
