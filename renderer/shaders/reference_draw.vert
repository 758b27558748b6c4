#version 450 core
// Object-space reference, draw (renderer/gl/reference_method.h): the tessellated skin parts with the camera of the
// main pass; each vertex carries its convolved diffuse radiance from a storage buffer indexed by the vertex index
// (gl_VertexID of an indexed draw), interpolated across the triangle: the far field (every source but the vertex
// itself) and the share of the vertex's own term, which the fragment multiplies by the main pass's E·α at its pixel
// (renderer/reference/surface_convolution.h, ownShare).
layout(location = 0) in vec3 position;  // world units

struct Convolved {
    vec4 far;    // rgb: diffuse radiance from the other sources after SSS (exposure applied)
    vec4 share;  // rgb: the weight of the vertex's own E·α in its output
};
layout(std430, binding = 0) readonly buffer ConvolvedDiffuse {
    Convolved convolved[];  // per vertex
};

uniform mat4 view;
uniform mat4 projection;

out vec3 scatteredFar;
out vec3 ownShare;
out float viewDepth;  // world units along the view axis, as the main pass's linear depth AOV

void main() {
    scatteredFar = convolved[gl_VertexID].far.rgb;
    ownShare = convolved[gl_VertexID].share.rgb;
    vec4 viewPosition = view * vec4(position, 1.0);
    viewDepth = -viewPosition.z;
    gl_Position = projection * viewPosition;
}
