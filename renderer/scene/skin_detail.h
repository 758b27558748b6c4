#pragma once
// Procedural skin detail of builtin:head (docs/scenes.md, "Skin detail of builtin:head"): an albedo map and a
// tangent-space normal map over the head surface's UV chart (builtin_geometry.h, headSurfaceAt), generated
// deterministically in code. Every feature is a function of the 3-D surface point in millimetres (so the chart's
// seam at the front, u = 0 = 1, and its poles show no discontinuity), sampled at the texel centres.
//
//  - normal map: a height field h (mm) of pores (cellular dimples, 0.28–0.45 mm radius, one per 1.3 mm cell or
//    none), fine criss-cross micro-relief lines (1.6 mm apart), forehead creases, crow's feet, nasolabial folds and
//    lip lines, turned into normals by central differences over the texels, divided by the true 3-D distance
//    between the neighbouring texels' surface points; encoded as 0.5 + 0.5 · (x, y, z), OpenGL convention
//    (x along ∂P/∂u, y along −∂P/∂v, as computeTangents orients the tangent frame);
//  - albedo map: a linear multiplier of the skin albedo (mean about 1): mottling and redness, cheek and nose
//    flush, sparse spots, darker pores, brow hair strokes and lip lines. Lips and brows themselves are the
//    head's vertex colours.
//
// Texel density: at kHeadDetailWidth × kHeadDetailHeight a texel spans about 0.28 mm (u) × 0.33 mm (v) on the
// face; the smallest feature (pore radius 0.28 mm, line width 0.3 mm) covers at least one texel, so the maps
// hold no detail finer than they can represent, and the renderer samples them mipmapped (trilinear, 8×
// anisotropic; gl/gpu_scene.cpp) so that no view aliases them. Row 0 (the crown pole, 0.2 mm around the vertex)
// is flat with albedo 1: the head's eyes sample it.
#include "renderer/scene/texture.h"

namespace skinlab::renderer {

inline constexpr int kHeadDetailWidth = 2048;
inline constexpr int kHeadDetailHeight = 1024;

struct SkinDetailMaps {
    Image albedo; // linear RGB multiplier, alpha 1
    Image normal; // tangent-space normal, 0.5 + 0.5 n, alpha 1
};

// The maps at width × height texels (width, height ≥ 4). Deterministic: the same size gives bit-identical maps.
// Uses up to std::thread::hardware_concurrency() threads (rows are independent).
SkinDetailMaps makeHeadSkinDetail(int width = kHeadDetailWidth, int height = kHeadDetailHeight);

} // namespace skinlab::renderer
