#pragma once
// Procedural, physically scaled models of the built-in scenes (builtin:halo, builtin:bleed, builtin:ear,
// builtin:head). They need no files; the builtin scene specs (renderer/scenes/builtin) add lights, camera and
// materials on top by material name.
//
// Conventions shared by every built-in model (docs/assets.md, "Built-in geometry"):
//  - 1 world unit = 1 millimetre (kBuiltinMillimetresPerUnit), so depth AOVs of built-in scenes are in mm;
//  - right-handed, +Y up, the model faces +Z: a camera on the +Z axis looking towards -Z sees its front;
//  - smooth, unit-length vertex normals; UVs in [0, 1] with v = 0 at the top of a texture image (the same
//    convention as Model from mesh_loader.h); unit tangents orthogonal to the normals, w = ±1 (see mesh.h);
//  - surfaces that meet at a sharp edge (sphere/backdrop, skin/paint) never share vertices, so every
//    attribute (normal, albedo, skin flag) is discontinuous exactly at the boundary;
//  - Model::parts are grouped by material; materials are named and their `skin` flag set; bounds computed.
#include "renderer/scene/mesh.h"

namespace skinlab::renderer {

// Millimetres per world unit of every built-in model.
inline constexpr float kBuiltinMillimetresPerUnit = 1.0f;

// --- builtin:halo -----------------------------------------------------------------------------------------
// A skin sphere of radius kHaloSphereRadiusMm centred at the origin, in front of a square non-skin backdrop
// plane (kHaloBackdropSizeMm wide, facing +Z) at z = -(kHaloSphereRadiusMm + depthGapMm): the gap between the
// back of the sphere and the backdrop along the viewing axis is exactly depthGapMm. Screen-space SSS that
// ignores depth discontinuities bleeds skin colour onto the backdrop around the silhouette (halos).
// Materials: "skin" (skin, albedo of light skin), "backdrop" (non-skin, grey 0.5).
inline constexpr float kHaloSphereRadiusMm = 40.0f;
inline constexpr float kHaloBackdropSizeMm = 600.0f;
// depthGapMm in (0, 10000]; throws InputError("builtin:halo: depth_gap_mm: ...") outside.
Model makeHaloScene(float depthGapMm = 200.0f);

// --- builtin:bleed ----------------------------------------------------------------------------------------
// A flat square skin patch (kBleedPatchSizeMm wide) in the plane z = 0, facing +Z, centred at the origin,
// with two non-skin squares kBleedSquareSizeMm wide inset at the same depth: "paint-dark" (albedo 0.02,
// centred at x = -kBleedSquareOffsetMm) and "paint-bright" (saturated green-blue, albedo (0.05, 0.6, 0.8),
// centred at x = +kBleedSquareOffsetMm), both at y = 0. The skin around them is a separate part with
// duplicated boundary vertices, so albedo and skin mask step sharply at the square edges (no depth step):
// only colour/material-aware SSS keeps skin colour off the paint and paint colour off the skin.
// Materials: "skin" (skin), "paint-dark" (non-skin), "paint-bright" (non-skin).
inline constexpr float kBleedPatchSizeMm = 160.0f;
inline constexpr float kBleedSquareSizeMm = 40.0f;
inline constexpr float kBleedSquareOffsetMm = 35.0f;
inline constexpr glm::vec3 kBleedDarkAlbedo{0.02f, 0.02f, 0.02f};
inline constexpr glm::vec3 kBleedBrightAlbedo{0.05f, 0.6f, 0.8f};
Model makeBleedScene();

// --- builtin:ear ------------------------------------------------------------------------------------------
// A thin curved skin fin, like an ear helix: a slab of constant thickness thicknessMm (measured along the
// surface normal), bent around the Y axis into a cylindrical arc (mid-surface radius kEarBendRadiusMm,
// opening angle kEarArcDeg, concave side towards +Z), kEarHeightMm tall, with a rounded rim. Its mid-surface
// passes through the origin; light it from behind (from -Z) and view it from +Z to see transmittance.
// Material: "skin" (skin).
inline constexpr float kEarBendRadiusMm = 30.0f;
inline constexpr float kEarArcDeg = 100.0f;
inline constexpr float kEarHeightMm = 60.0f;
// thicknessMm in (0, 20]; throws InputError("builtin:ear: thickness_mm: ...") outside.
Model makeEarScene(float thicknessMm = 2.5f);

// --- builtin:head -----------------------------------------------------------------------------------------
// A recognisable procedural adult head, about 229 mm from chin to vertex, 152 mm wide (without ears) and
// about 195 mm from brow to back, centred near the origin and facing +Z: a deformed superellipsoid with a
// nose, brow ridge, chin, cheekbones, eye sockets, lips and two ears, plus a neck stub. Albedo variation is carried in
// Vertex::color (multiplying the "skin" material albedo): redder lips, darker eyebrows. The eyes are
// separate non-skin spheres (material "eye"). 51,712 triangles.
// With skinDetail (the default) the model also brings procedural skin maps (skin_detail.h): an albedo map
// (mottling, redness, spots, brow hairs, lip lines) and a tangent-space normal map (pores, fine wrinkles), over
// the head surface's UVs; the ears and the neck use UVs inside the back of the head's chart (generic skin) and the
// eyes one flat texel (row 0, the crown pole). Without it (model.skin_detail = false) the head is smooth.
// Materials: "skin" (skin), "eye" (non-skin).
// Landmarks (mm, for tests and camera/light placement):
// (measured on the generated mesh; the tests check them to ±1 mm).
inline constexpr float kHeadVertexY = 116.0f;      // top of the head (vertex)
inline constexpr float kHeadChinY = -113.0f;       // lowest point of the chin (menton)
inline constexpr float kHeadNoseTipZ = 113.4f;     // nose tip (pronasale), the most anterior point, at y ≈ -31
inline constexpr float kHeadEarOuterX = 86.8f;     // outer rim of each ear, |x|
inline constexpr float kHeadNeckBottomY = -175.0f; // the neck stub's flat bottom (the model's lowest point)
Model makeHeadScene(bool skinDetail = true);
// The head surface (without ears, eyes and neck) at its UV (u around from the front, towards +X first; v from the
// top, v = 0 at the vertex): the parametric surface the head's grid samples; its texture maps are laid out on it.
glm::vec3 headSurfaceAt(float u, float v);

} // namespace skinlab::renderer
