#pragma once
// Loading triangle meshes from files through assimp: glTF 2.0 (.glb, .gltf) and Wavefront OBJ (.obj), plus
// whatever else assimp reads (untested).
#include "renderer/scene/mesh.h"

#include <filesystem>

namespace skinlab::renderer {

// Options for files that break their format's conventions.
struct ModelLoadOptions {
    // Replace v by 1 - v after import. For files whose UVs put v = 0 at the image BOTTOM although the format
    // (glTF) says top: the Lee Perry-Smith scan (LeePerrySmith.glb, converted for three.js, which samples it
    // with flipped textures) is one; docs/assets.md shows how that was established.
    bool flipV = false;
};

// Loads every mesh of the file's scene graph into one Model, in the file's own units (the scene spec gives
// mm_per_unit):
//  - node transforms are applied (positions by the node's world matrix, normals and tangents by its
//    inverse-transpose), so the Model is in the file's world space;
//  - polygons are triangulated, identical vertices joined, degenerate triangles removed;
//  - normals: the file's, else generated smooth (assimp, 80° crease angle); always re-normalised;
//  - UV0: the file's (other UV sets ignored), with v = 0 at the TOP of the texture image (assimp's UVs are
//    flipped on import, for glTF as well as OBJ), so a texture uploaded top row first samples correctly
//    (options.flipV: v = 1 - v for files that break this);
//    a mesh without UVs gets (0, 0);
//  - tangents: always computed here from UV0 (per-triangle ∂P/∂u accumulated per vertex, area- and angle-
//    weighted, Gram-Schmidt against the normal): xyz = unit tangent towards increasing u; w = ±1 such that
//    the bitangent B = w * cross(N, T) points UP the texture image (towards decreasing v), the OpenGL /
//    glTF convention of tangent-space normal maps (green = up); mapped normal = normalize(T*m.x + B*m.y +
//    N*m.z) with m = 2*texel - 1. Without UVs a tangent perpendicular to N is chosen, w = +1;
//  - one SubMesh per assimp mesh, in scene-graph order; materials keep their names ("material-N" when
//    unnamed); albedo = glTF baseColorFactor or OBJ/assimp diffuse colour (taken as linear); skin = true
//    (the scene spec decides which materials are skin); Vertex::color = 1, Vertex::skin = 1;
//  - bounds computed.
// Errors: missing file, unreadable or corrupt file, a file without triangle meshes →
// InputError "PATH: cannot load model (assimp: MESSAGE)" (or "... (no triangle meshes)").
Model loadModel(const std::filesystem::path& path, const ModelLoadOptions& options = {});

} // namespace skinlab::renderer
