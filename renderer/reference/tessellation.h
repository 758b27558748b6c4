#pragma once
// Tessellation of a model's skin parts for the object-space reference (docs/extensions.md, "The reference").
//
// The reference samples irradiance at mesh vertices, so the skin surface must be sampled densely: every skin
// triangle is split 1 → 4 at its edge midpoints, in rounds, until the longest skin edge is at most the target edge
// length (mm). Every round splits *all* skin triangles (not only the long ones) so the mesh stays conforming: a
// shared edge is split once, by an edge map, and no T-junctions appear inside the skin. Midpoints lie on the
// original flat triangles, so the surface does not change (only its sampling does); attributes are interpolated
// linearly (normal and tangent re-normalised). Non-skin parts neither scatter nor receive, so they are kept as is.
//
// Vertex indices of the input are preserved (new vertices are appended), so values at the original vertices can be
// compared across densities.
#include "renderer/scene/mesh.h"

#include <cstddef>

namespace skinlab::renderer::reference {

struct TessellationStatistics {
    int rounds = 0;                 // 1 → 4 rounds applied
    float longestSkinEdgeMm = 0.0f; // after tessellation
    std::size_t skinTriangles = 0;  // after tessellation
};

// Default limit on the output's vertex count: 8 million vertices ≈ 0.6 GB of Vertex data.
inline constexpr std::size_t kMaxReferenceVertices = 8'000'000;

// Splits the skin parts (parts whose material has skin = true) until no skin edge is longer than targetEdgeMm.
// Throws InputError ("reference: edge_mm: ...") when the target would exceed maxVertices, and for a non-positive
// target or mmPerUnit.
Model tessellateSkin(const Model& model, float targetEdgeMm, float mmPerUnit,
                     TessellationStatistics* statistics = nullptr, std::size_t maxVertices = kMaxReferenceVertices);

// Longest edge (mm) of the triangles of the skin parts.
float longestSkinEdgeMm(const Model& model, float mmPerUnit);

} // namespace skinlab::renderer::reference
