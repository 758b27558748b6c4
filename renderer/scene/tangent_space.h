#pragma once
// Per-vertex tangent frames from UVs, shared by the mesh loader and the procedural geometry so that every
// Model follows one tangent convention (mesh.h, mesh_loader.h).
#include "renderer/scene/mesh.h"

namespace skinlab::renderer {

// Computes Vertex::tangent for every vertex referenced by `model.indices` from positions, normals and UVs:
// per triangle ∂P/∂u and ∂P/∂v, accumulated per vertex weighted by the triangle's corner angle (as MikkTSpace
// does), then Gram-Schmidt against the vertex normal. xyz = unit tangent towards increasing u, orthogonal to
// the normal; w = ±1 chosen so that the bitangent w * cross(N, T) points towards DECREASING v, i.e. up the
// texture image (v = 0 is the image top): the OpenGL/glTF normal-map convention (green = up). Vertices whose
// triangles have no usable UV gradient get an arbitrary unit tangent perpendicular to the normal, w = +1.
// Normals must already be unit length.
void computeTangents(Model& model);

} // namespace skinlab::renderer
