#version 450 core
// One triangle covering the viewport (vertices (-1,-1), (3,-1), (-1,3)); no vertex attributes.
// texCoord is 0..1 across the viewport; clip z = 1 (the far plane), so passes that draw "behind everything"
// can depth-test against the scene with GL_LEQUAL.
out vec2 texCoord;

void main() {
    vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    texCoord = corner;
    gl_Position = vec4(corner * 2.0 - 1.0, 1.0, 1.0);
}
