#pragma once
// Tessellation of a model's skin parts for the object-space reference (docs/extensions.md, "The reference").
//
// The reference samples irradiance at mesh vertices, so the skin surface must be sampled densely, but only as
// densely as the target edge length asks: refinement is adaptive. Each round marks every skin edge longer than
// the target, adds to the marks the longest edge of every triangle that has a marked edge (closure), and splits
// each skin triangle by its marked edges (red-green-blue refinement, Carstensen 2004; Bänsch 1991): none → kept,
// its longest edge only → 2 triangles (longest-edge bisection), the longest and one more → 3 (the second cut runs
// from the longest edge's midpoint), all three → 4 at the midpoints. Rounds repeat until no skin edge is longer
// than the target. Because every split triangle is cut through its longest edge first, angles stay bounded away
// from 0 (no slivers); because a marked edge gets one midpoint through an edge map shared by both of its
// triangles, the skin mesh stays conforming (no T-junctions). Triangles already short enough are left alone
// unless a neighbour's closure reaches them, so a mesh of mixed triangle sizes (a scanned head, builtin:head) is
// refined only where its triangles are long. Midpoints lie on the original flat triangles, so the surface does not
// change (only its sampling does); attributes are interpolated linearly (normal and tangent re-normalised).
// Non-skin parts neither scatter nor receive, so they are kept as is.
//
// Vertex indices of the input are preserved (new vertices are appended), so values at the original vertices can be
// compared across densities.
#include "renderer/scene/mesh.h"

#include <cstddef>

namespace skinlab::renderer::reference {

struct TessellationStatistics {
    int rounds = 0;                 // refinement rounds applied
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
