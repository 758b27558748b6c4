#version 450 core
// Object-space reference, bake (renderer/gl/reference_method.h): draws the tessellated mesh as GL_POINTS, one point
// per vertex at pixel (i mod W, i div W) of the bake target (i = gl_VertexID = the vertex's index), and hands
// main_pass.frag exactly the varyings main_pass.vert hands it, so the unchanged main-pass shading (lights ×
// shadow + IBL × AO, × albedo, × exposure) is evaluated at every vertex. Points are rasterised with constant
// varyings, so main_pass.frag's implicit texture derivatives are 0: maps are sampled at level 0 at the vertex uv.
layout(location = 0) in vec3 position;   // world units
layout(location = 1) in vec3 normal;     // unit, world space
layout(location = 2) in vec2 uv;
layout(location = 3) in vec4 tangent;
layout(location = 4) in vec3 color;
layout(location = 5) in float skin;

uniform int bakeWidth;   // pixels per row of the bake target
uniform int bakeHeight;  // rows

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
    ivec2 pixel = ivec2(gl_VertexID % bakeWidth, gl_VertexID / bakeWidth);
    vec2 ndc = (vec2(pixel) + 0.5) / vec2(bakeWidth, bakeHeight) * 2.0 - 1.0;  // the pixel's centre
    gl_Position = vec4(ndc, 0.0, 1.0);
    gl_PointSize = 1.0;
}
