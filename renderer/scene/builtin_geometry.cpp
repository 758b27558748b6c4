#include "renderer/scene/builtin_geometry.h"

#include "common/error.h"
#include "renderer/scene/skin_detail.h"
#include "renderer/scene/tangent_space.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <numbers>
#include <sstream>
#include <string>
#include <unordered_map>

namespace skinlab::renderer {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// Linear albedo of the built-in skin material: a light skin tone. Linear (not sRGB) reflectance, in the range
// reported for light skin at 450/550/650 nm by spectrophotometry (roughly 0.3–0.6); the scene spec can override
// it by material name.
constexpr glm::vec3 kSkinAlbedo{0.60f, 0.42f, 0.34f};

// One part (one material) under construction: positions, UVs, colours and triangles; normals come last.
struct Surface {
    std::vector<Vertex> vertices;
    std::vector<std::uint32_t> indices;
};

// A (columns + 1) × (rows + 1) grid of vertices over a parametric surface position(s, t), s, t ∈ [0, 1],
// two triangles per cell. With wrapColumns the last column reuses the bit-identical positions of the first
// (so normals weld across the seam) but keeps u = 1 (so UVs do not jump). UV = (s, t). keepCell(i, j) selects
// cells (default: all). Triangles whose area is zero (grid poles) are skipped. Winding is fixed by orient().
void addGrid(Surface& surface, int columns, int rows, bool wrapColumns,
             const std::function<glm::vec3(float s, float t)>& position,
             const std::function<bool(int column, int row)>& keepCell = {}) {
    const auto base = static_cast<std::uint32_t>(surface.vertices.size());
    for (int j = 0; j <= rows; ++j) {
        const float t = static_cast<float>(j) / static_cast<float>(rows);
        for (int i = 0; i <= columns; ++i) {
            const int positionColumn = (wrapColumns && i == columns) ? 0 : i;
            const float s = static_cast<float>(positionColumn) / static_cast<float>(columns);
            Vertex vertex;
            vertex.position = position(s, t);
            vertex.uv = glm::vec2(static_cast<float>(i) / static_cast<float>(columns), t);
            surface.vertices.push_back(vertex);
        }
    }
    const auto at = [&](int i, int j) { return base + static_cast<std::uint32_t>(j * (columns + 1) + i); };
    const auto addTriangle = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
        const glm::vec3 cross = glm::cross(surface.vertices[b].position - surface.vertices[a].position,
                                           surface.vertices[c].position - surface.vertices[a].position);
        if (glm::dot(cross, cross) <= 0.0f) return;
        surface.indices.insert(surface.indices.end(), {a, b, c});
    };
    for (int j = 0; j < rows; ++j) {
        for (int i = 0; i < columns; ++i) {
            if (keepCell && !keepCell(i, j)) continue;
            addTriangle(at(i, j), at(i + 1, j), at(i, j + 1));
            addTriangle(at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
        }
    }
}

// Drops vertices no triangle references (cells left out by keepCell), renumbering the indices.
void removeUnreferenced(Surface& surface) {
    std::vector<std::int64_t> remap(surface.vertices.size(), -1);
    std::vector<Vertex> kept;
    for (std::uint32_t& index : surface.indices) {
        if (remap[index] < 0) {
            remap[index] = static_cast<std::int64_t>(kept.size());
            kept.push_back(surface.vertices[index]);
        }
        index = static_cast<std::uint32_t>(remap[index]);
    }
    surface.vertices = std::move(kept);
}

void transformPositions(Surface& surface, const glm::mat4& transform) {
    for (Vertex& vertex : surface.vertices) vertex.position = glm::vec3(transform * glm::vec4(vertex.position, 1.0f));
}

// Makes every triangle counter-clockwise seen from the side `outward(position)` points to: if the summed
// agreement of face normals with the hint is negative, all triangles are flipped. For a closed surface with
// outward(p) = p − centre the sum is 3 × the signed volume (divergence theorem), so closed surfaces come out
// facing outwards whatever their shape.
void orient(Surface& surface, const std::function<glm::vec3(const glm::vec3&)>& outward) {
    double agreement = 0.0;
    for (std::size_t t = 0; t + 2 < surface.indices.size(); t += 3) {
        const glm::vec3& a = surface.vertices[surface.indices[t]].position;
        const glm::vec3& b = surface.vertices[surface.indices[t + 1]].position;
        const glm::vec3& c = surface.vertices[surface.indices[t + 2]].position;
        agreement += glm::dot(glm::cross(b - a, c - a), outward((a + b + c) / 3.0f));
    }
    if (agreement < 0.0) {
        for (std::size_t t = 0; t + 2 < surface.indices.size(); t += 3) {
            std::swap(surface.indices[t + 1], surface.indices[t + 2]);
        }
    }
}

// Smooth normals: angle-weighted face normals accumulated over all vertices of the surface that share a
// bit-identical position (grid seams and poles), so the shading is smooth across them. Different surfaces
// never share normals, which keeps material boundaries and creases between parts sharp.
void smoothNormals(Surface& surface) {
    struct PositionHash {
        std::size_t operator()(const glm::vec3& p) const {
            // + 0.0f turns -0 into +0: equal positions must hash equally.
            const glm::vec3 canonical = p + glm::vec3(0.0f);
            std::uint32_t bits[3];
            std::memcpy(bits, &canonical, sizeof bits);
            return (static_cast<std::size_t>(bits[0]) * 73856093u) ^ (static_cast<std::size_t>(bits[1]) * 19349663u) ^
                   (static_cast<std::size_t>(bits[2]) * 83492791u);
        }
    };
    std::unordered_map<glm::vec3, glm::vec3, PositionHash> sums;
    for (std::size_t t = 0; t + 2 < surface.indices.size(); t += 3) {
        const glm::vec3 p[3] = {surface.vertices[surface.indices[t]].position,
                                surface.vertices[surface.indices[t + 1]].position,
                                surface.vertices[surface.indices[t + 2]].position};
        const glm::vec3 face = glm::normalize(glm::cross(p[1] - p[0], p[2] - p[0]));
        for (int k = 0; k < 3; ++k) {
            const glm::vec3 e1 = glm::normalize(p[(k + 1) % 3] - p[k]);
            const glm::vec3 e2 = glm::normalize(p[(k + 2) % 3] - p[k]);
            const float angle = std::acos(std::clamp(glm::dot(e1, e2), -1.0f, 1.0f));
            sums[p[k]] += angle * face;
        }
    }
    for (Vertex& vertex : surface.vertices) {
        const auto found = sums.find(vertex.position);
        if (found == sums.end() || glm::length(found->second) <= 0.0f) continue;
        vertex.normal = glm::normalize(found->second);
    }
}

// Appends a finished surface to the model as one part with the given material.
void appendPart(Model& model, const Surface& surface, std::uint32_t material) {
    const auto base = static_cast<std::uint32_t>(model.vertices.size());
    const auto first = static_cast<std::uint32_t>(model.indices.size());
    model.vertices.insert(model.vertices.end(), surface.vertices.begin(), surface.vertices.end());
    for (std::uint32_t index : surface.indices) model.indices.push_back(base + index);
    model.parts.push_back(SubMesh{first, static_cast<std::uint32_t>(surface.indices.size()), material});
}

std::uint32_t addMaterial(Model& model, std::string name, glm::vec3 albedo, bool skin, float glossiness) {
    MeshMaterial material;
    material.name = std::move(name);
    material.albedo = albedo;
    material.skin = skin;
    material.glossiness = glossiness;
    model.materials.push_back(material);
    return static_cast<std::uint32_t>(model.materials.size() - 1);
}

void finishModel(Model& model) {
    computeTangents(model);
    model.computeBounds();
}

// Unit direction of grid parameters (s around from the front, t from the top): the equirectangular
// convention of environment.h rotated so that s = 0 faces +Z (the model's front).
glm::vec3 sphereDirection(float s, float t) {
    // Exact poles: sin(pi) is not 0 in float, and every vertex of a pole row must weld to one position.
    if (t <= 0.0f) return {0.0f, 1.0f, 0.0f};
    if (t >= 1.0f) return {0.0f, -1.0f, 0.0f};
    const float theta = kPi * t;
    const float phi = 2.0f * kPi * s;
    return {std::sin(theta) * std::sin(phi), std::cos(theta), std::sin(theta) * std::cos(phi)};
}

Surface makeSphere(float radius, int columns, int rows) {
    Surface surface;
    addGrid(surface, columns, rows, true, [radius](float s, float t) { return radius * sphereDirection(s, t); });
    orient(surface, [](const glm::vec3& p) { return p; });
    return surface;
}

// A closed, thin, curved fin (builtin:ear and the head's ears), in local coordinates: an elliptical outline
// with half-extents halfWidth (arc length along the bend) and halfHeight (along Y), constant thickness with a
// semicircular rim, its mid-surface bent around the axis x = 0, z = bendRadius (concave side towards +Z) and
// passing through the origin. Grid columns run around the outline, rows across the profile: front face
// (offset +thickness/2 from the mid-surface towards the bend axis) from its centre out to the rim, the rim's
// half circle, the back face (offset −thickness/2) back to its centre.
Surface makeFin(float halfWidth, float halfHeight, float thickness, float bendRadius, int columns, int flatRows,
                int rimRows) {
    const float half = 0.5f * thickness;
    const int rows = 2 * flatRows + rimRows;
    const auto position = [=](float s, float t) {
        const float phi = 2.0f * kPi * s;
        const glm::vec2 outline(halfWidth * std::cos(phi), halfHeight * std::sin(phi));
        const float boundary = glm::length(outline); // distance from the centre to the outline, mm
        const glm::vec2 direction = outline / boundary;
        const float flat = boundary - half; // where the rim starts
        const float row = t * static_cast<float>(rows);
        float radial = 0.0f;
        float offset = 0.0f;
        if (row <= static_cast<float>(flatRows)) {
            radial = flat * row / static_cast<float>(flatRows);
            offset = half;
        } else if (row <= static_cast<float>(flatRows + rimRows)) {
            const float beta = kPi * (row - static_cast<float>(flatRows)) / static_cast<float>(rimRows);
            radial = flat + half * std::sin(beta);
            offset = half * std::cos(beta);
        } else {
            radial = flat * (static_cast<float>(rows) - row) / static_cast<float>(flatRows);
            offset = -half;
        }
        // Exact ends of the rim and poles, so that positions weld bit-identically.
        if (row >= static_cast<float>(rows)) radial = 0.0f;
        const glm::vec2 planar = radial * direction; // (arc length, height)
        const float alpha = planar.x / bendRadius;   // bend angle, rad
        const float distance = bendRadius - offset;  // distance from the bend axis
        return glm::vec3(distance * std::sin(alpha), planar.y, bendRadius - distance * std::cos(alpha));
    };
    Surface surface;
    addGrid(surface, columns, rows, true, position);
    // Outward hint relative to the fin's centre (a point on the mid-surface): the volume criterion of orient().
    orient(surface, [](const glm::vec3& p) { return p; });
    return surface;
}

// Shortest round-trip text of a number for error messages ("0.5", "20000", "-1").
std::string formatNumber(float value) {
    std::ostringstream text;
    text << value;
    return text.str();
}

float smoothStep(float edge0, float edge1, float x) {
    const float t = std::clamp((x - edge0) / (edge1 - edge0), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

float gaussian(float value, float centre, float sigma) {
    const float d = (value - centre) / sigma;
    return std::exp(-0.5f * d * d);
}

} // namespace

Model makeHaloScene(float depthGapMm) {
    if (!(depthGapMm > 0.0f) || depthGapMm > 10000.0f) {
        throwInput("builtin:halo", "depth_gap_mm", formatNumber(depthGapMm) + " is out of range (0, 10000]");
    }
    Model model;
    const std::uint32_t skin = addMaterial(model, "skin", kSkinAlbedo, true, 0.6f);
    const std::uint32_t backdrop = addMaterial(model, "backdrop", glm::vec3(0.5f), false, 0.3f);

    // 128 × 64 cells: 1.96 mm per cell along the equator, fine enough for a smooth silhouette at 1080p.
    Surface sphere = makeSphere(kHaloSphereRadiusMm, 128, 64);
    smoothNormals(sphere);
    appendPart(model, sphere, skin);

    const float planeZ = -(kHaloSphereRadiusMm + depthGapMm);
    const float halfSize = 0.5f * kHaloBackdropSizeMm;
    Surface plane;
    // 16 × 16 cells: a flat plane needs none for its shape, but small triangles keep per-vertex lighting
    // (and depth interpolation on any rasteriser) well conditioned.
    addGrid(plane, 16, 16, false, [=](float s, float t) {
        return glm::vec3(-halfSize + s * kHaloBackdropSizeMm, halfSize - t * kHaloBackdropSizeMm, planeZ);
    });
    orient(plane, [](const glm::vec3&) { return glm::vec3(0.0f, 0.0f, 1.0f); });
    smoothNormals(plane);
    appendPart(model, plane, backdrop);
    finishModel(model);
    return model;
}

Model makeBleedScene() {
    Model model;
    const std::uint32_t skin = addMaterial(model, "skin", kSkinAlbedo, true, 0.6f);
    const std::uint32_t dark = addMaterial(model, "paint-dark", kBleedDarkAlbedo, false, 0.3f);
    const std::uint32_t bright = addMaterial(model, "paint-bright", kBleedBrightAlbedo, false, 0.3f);

    // One 32 × 32 grid of 5 mm cells over the patch; the square edges (±15, ±55 in x, ±20 in y) fall on
    // cell edges. Each part is built from its own cells with its own vertices: duplicated along the square
    // boundaries, so material, albedo and skin mask step within zero distance and depth is the same plane.
    constexpr int cells = 32;
    const float half = 0.5f * kBleedPatchSizeMm;
    const float cellSize = kBleedPatchSizeMm / cells;
    const auto regionOf = [&](int i, int j) {
        const float x = -half + (static_cast<float>(i) + 0.5f) * cellSize;
        const float y = half - (static_cast<float>(j) + 0.5f) * cellSize;
        const float halfSquare = 0.5f * kBleedSquareSizeMm;
        if (std::abs(y) < halfSquare) {
            if (std::abs(x + kBleedSquareOffsetMm) < halfSquare) return dark;
            if (std::abs(x - kBleedSquareOffsetMm) < halfSquare) return bright;
        }
        return skin;
    };
    const auto position = [=](float s, float t) {
        return glm::vec3(-half + s * kBleedPatchSizeMm, half - t * kBleedPatchSizeMm, 0.0f);
    };
    for (const std::uint32_t material : {skin, dark, bright}) {
        Surface surface;
        addGrid(surface, cells, cells, false, position, [&](int i, int j) { return regionOf(i, j) == material; });
        removeUnreferenced(surface);
        orient(surface, [](const glm::vec3&) { return glm::vec3(0.0f, 0.0f, 1.0f); });
        smoothNormals(surface);
        appendPart(model, surface, material);
    }
    finishModel(model);
    return model;
}

Model makeEarScene(float thicknessMm) {
    if (!(thicknessMm > 0.0f) || thicknessMm > 20.0f) {
        throwInput("builtin:ear", "thickness_mm", formatNumber(thicknessMm) + " is out of range (0, 20]");
    }
    Model model;
    const std::uint32_t skin = addMaterial(model, "skin", kSkinAlbedo, true, 0.6f);
    const float halfWidth = 0.5f * kEarBendRadiusMm * kEarArcDeg * kPi / 180.0f; // half the arc length, mm
    // 128 columns around the outline, 40 rows per face (0.7 mm radial steps) and 16 across the rim.
    Surface fin = makeFin(halfWidth, 0.5f * kEarHeightMm, thicknessMm, kEarBendRadiusMm, 128, 40, 16);
    smoothNormals(fin);
    appendPart(model, fin, skin);
    finishModel(model);
    return model;
}

// ------------------------------------------------------------------------------------------------------------
// The procedural head. Proportions of a typical adult man: head length (glabella–back) ≈ 195 mm and head
// breadth ≈ 155 mm (Pheasant & Haslegrave, Bodyspace, 3rd ed., British men, 50th percentile), menton–vertex
// height ≈ 230 mm. Built as a deformed superellipsoid (the cranium and face) plus separate closed parts that
// intersect it: ears (thick curved fins), eyeballs (non-skin spheres) and a neck stub.
namespace {

// Semi-axes of the base ellipsoid, mm (x: breadth/2, y: height/2, z: length/2).
constexpr glm::vec3 kHeadSemiAxes{76.0f, 116.0f, 97.0f};
constexpr float kEyeRadius = 12.0f;          // eyeball radius, mm (adult ≈ 12)
constexpr glm::vec2 kEyeCentre{32.0f, 4.0f}; // |x|, y of the eye centres (interpupillary distance ≈ 64 mm)
constexpr float kMouthY = -66.0f;

// Point of the head surface for unit direction d of the base ellipsoid (front = +Z, up = +Y).
glm::vec3 headSurface(const glm::vec3& d) {
    const glm::vec3 n = glm::normalize(d / kHeadSemiAxes); // normal of the base ellipsoid
    // A superellipsoid (|x|^e + |y|^e + |z|^e = 1 in units of the semi-axes) with e = 2.5 instead of an
    // ellipsoid: c -> sign(c) |c|^(2/e) maps the unit sphere onto it. Fuller temples and crown: a plain
    // ellipsoid of these proportions reads as an egg.
    constexpr float exponent = 2.0f / 2.5f;
    const auto power = [](float c) { return std::copysign(std::pow(std::abs(c), exponent), c); };
    glm::vec3 p = glm::vec3(power(d.x), power(d.y), power(d.z)) * kHeadSemiAxes;
    // How much a point belongs to the face (front, |x| not too large): features below are masked with it.
    const float front = smoothStep(0.35f, 0.75f, n.z);

    // Lower face and jaw: the face narrows towards the chin and the lower back pulls in towards the neck.
    const float lower = smoothStep(-10.0f, -112.0f, p.y);
    p.x *= 1.0f - 0.24f * lower;
    if (p.z < 0.0f) p.z *= 1.0f - 0.30f * lower;
    // Forehead and face slightly flattened at the front, so it reads as a face rather than a ball.
    if (p.z > 0.0f) p.z *= 1.0f - 0.06f * front;

    float displacement = 0.0f;
    // Nose: a ridge from the bridge (y ≈ +8) to the tip (y ≈ −30), widening downwards, ending in a rounded
    // tip; then a sharp drop to the upper lip. Heights along the base normal, mm.
    {
        const float along = std::clamp((8.0f - p.y) / 38.0f, 0.0f, 1.0f); // 0 at the bridge, 1 at the tip
        const float ridge =
            (5.0f + 14.0f * along * along) * smoothStep(14.0f, 4.0f, p.y) * smoothStep(-44.0f, -30.0f, p.y);
        const float tip = 6.0f * gaussian(p.y, -28.0f, 6.0f);
        const float width = 7.0f + 7.0f * along; // half width, mm
        displacement += (ridge + tip) * gaussian(p.x, 0.0f, width) * front;
        // Nostril wings (alae): small bulges either side of the tip.
        displacement +=
            7.0f * (gaussian(p.x, -13.0f, 4.5f) + gaussian(p.x, 13.0f, 4.5f)) * gaussian(p.y, -35.0f, 4.5f) * front;
    }
    // Brow ridge above the eyes.
    displacement += 6.0f * gaussian(p.y, 22.0f, 6.0f) * gaussian(p.x, 0.0f, 34.0f) * front;
    // Eye sockets.
    displacement -= 13.0f * (gaussian(p.x, -kEyeCentre.x, 12.0f) + gaussian(p.x, kEyeCentre.x, 12.0f)) *
                    gaussian(p.y, kEyeCentre.y, 9.0f) * front;
    // Cheekbones.
    displacement +=
        7.0f * (gaussian(p.x, -46.0f, 13.0f) + gaussian(p.x, 46.0f, 13.0f)) * gaussian(p.y, -18.0f, 12.0f) * front;
    // Lips: upper and lower lip bulges with a small gap between them at the mouth line.
    displacement += 7.0f * gaussian(p.x, 0.0f, 20.0f) *
                    (gaussian(p.y, kMouthY + 6.0f, 4.0f) + gaussian(p.y, kMouthY - 6.5f, 4.5f)) * front;
    // Chin.
    displacement += 11.0f * gaussian(p.x, 0.0f, 17.0f) * gaussian(p.y, -100.0f, 11.0f) * front;
    return p + displacement * n;
}

// Linear albedo multiplier of the head's skin (Vertex::color) at a surface point: redder lips, darker brows.
glm::vec3 headColour(const glm::vec3& p) {
    if (p.z < 40.0f) return glm::vec3(1.0f);
    glm::vec3 colour(1.0f);
    // Lips (vermilion): an ellipse around the mouth, soft edged over ~2 mm.
    const float lipX = p.x / 24.0f;
    const float lipY = (p.y - kMouthY) / 12.0f;
    const float lips = smoothStep(1.0f, 0.8f, std::sqrt(lipX * lipX + lipY * lipY));
    colour = glm::mix(colour, glm::vec3(1.05f, 0.62f, 0.62f), lips);
    // Eyebrows: arcs above each eye (x from 12 to 52 mm), 7 mm tall, darker and less red than skin.
    for (const float side : {-1.0f, 1.0f}) {
        const float x = side * p.x;
        const float arcY = 19.0f + 4.0f * std::sin(kPi * std::clamp((x - 12.0f) / 40.0f, 0.0f, 1.0f));
        const float brow =
            smoothStep(4.5f, 2.5f, std::abs(p.y - arcY)) * smoothStep(10.0f, 14.0f, x) * smoothStep(54.0f, 48.0f, x);
        colour = glm::mix(colour, glm::vec3(0.30f, 0.26f, 0.24f), brow);
    }
    return colour;
}

// Maps a part's own UVs (in [0, 1]²) linearly into the rectangle [u0, u1] × [v0, v1] of the head's chart.
void remapUVs(Surface& surface, float u0, float u1, float v0, float v1) {
    for (Vertex& vertex : surface.vertices)
        vertex.uv = glm::vec2(u0 + (u1 - u0) * vertex.uv.x, v0 + (v1 - v0) * vertex.uv.y);
}

} // namespace

glm::vec3 headSurfaceAt(float u, float v) { return headSurface(sphereDirection(u, v)); }

Model makeHeadScene(bool skinDetail) {
    Model model;
    const std::uint32_t skin = addMaterial(model, "skin", kSkinAlbedo, true, 0.6f);
    const std::uint32_t eye = addMaterial(model, "eye", glm::vec3(0.8f, 0.78f, 0.75f), false, 0.95f);

    // Head: 192 × 112 cells, ≈ 2.6 mm edges at the face (43k triangles).
    Surface head;
    addGrid(head, 192, 112, true, [](float s, float t) { return headSurface(sphereDirection(s, t)); });
    orient(head, [](const glm::vec3& p) { return p; });
    for (Vertex& vertex : head.vertices) vertex.color = headColour(vertex.position);
    smoothNormals(head);
    appendPart(model, head, skin);

    // Ears: curved fins 64 mm tall, 40 mm wide, 5 mm thick, concave side turned outwards and 25° forwards,
    // their front edge buried in the side of the head.
    for (const float side : {1.0f, -1.0f}) {
        Surface ear = makeFin(20.0f, 32.0f, 5.0f, 26.0f, 48, 10, 8);
        // Local +Z (the concave side) → outwards-forwards (rotation about Y by 65°), then to the side of the head.
        glm::mat4 transform(1.0f);
        transform = glm::translate(transform, glm::vec3(side * 72.0f, -12.0f, -8.0f));
        transform = glm::scale(transform, glm::vec3(side, 1.0f, 1.0f));
        transform = glm::rotate(transform, glm::radians(65.0f), glm::vec3(0.0f, 1.0f, 0.0f));
        transform = glm::rotate(transform, glm::radians(-8.0f), glm::vec3(1.0f, 0.0f, 0.0f)); // top leans back
        transformPositions(ear, transform);
        const glm::vec3 centre(transform[3]);
        orient(ear, [centre](const glm::vec3& p) { return p - centre; });
        smoothNormals(ear);
        // Behind the ear on the back of the head's chart: generic skin detail, no facial features.
        remapUVs(ear, 0.40f, 0.52f, 0.36f, 0.56f);
        appendPart(model, ear, skin);
    }

    // Eyeballs: centred behind the socket so that the cornea sits ~3 mm in front of the socket floor.
    for (const float side : {1.0f, -1.0f}) {
        // The socket floor: the head surface on the base-ellipsoid direction through the eye centre.
        const float dx = side * kEyeCentre.x / kHeadSemiAxes.x;
        const float dy = kEyeCentre.y / kHeadSemiAxes.y;
        const glm::vec3 socket = headSurface(glm::vec3(dx, dy, std::sqrt(1.0f - dx * dx - dy * dy)));
        Surface ball = makeSphere(kEyeRadius, 32, 16);
        transformPositions(ball, glm::translate(glm::mat4(1.0f), glm::vec3(side * kEyeCentre.x, kEyeCentre.y,
                                                                           socket.z - kEyeRadius + 3.0f)));
        smoothNormals(ball);
        // One texel of the maps' flat row 0: the skin detail does not reach the eyes.
        for (Vertex& vertex : ball.vertices) vertex.uv = glm::vec2(0.5f, 0.5f / static_cast<float>(kHeadDetailHeight));
        appendPart(model, ball, eye);
    }

    // Neck stub: a vertical cylinder (radius 52 mm) from inside the head down to y = -175 mm, closed below.
    {
        constexpr float radius = 52.0f;
        constexpr float top = -55.0f;
        constexpr float bottom = kHeadNeckBottomY;
        constexpr float centreZ = -18.0f;
        Surface side;
        addGrid(side, 64, 12, true, [=](float s, float t) {
            const float phi = 2.0f * kPi * s;
            return glm::vec3(radius * std::sin(phi), top + t * (bottom - top), centreZ + radius * std::cos(phi));
        });
        orient(side, [=](const glm::vec3& p) { return glm::vec3(p.x, 0.0f, p.z - centreZ); });
        smoothNormals(side);
        remapUVs(side, 0.25f, 0.75f, 0.72f, 0.80f); // the back of the lower head's chart: generic skin
        appendPart(model, side, skin);
        Surface cap;
        addGrid(cap, 64, 4, true, [=](float s, float t) {
            const float phi = 2.0f * kPi * s;
            return glm::vec3(t * radius * std::sin(phi), bottom, centreZ + t * radius * std::cos(phi));
        });
        orient(cap, [](const glm::vec3&) { return glm::vec3(0.0f, -1.0f, 0.0f); });
        smoothNormals(cap);
        remapUVs(cap, 0.45f, 0.55f, 0.60f, 0.62f);
        appendPart(model, cap, skin);
    }
    finishModel(model);
    if (skinDetail) {
        SkinDetailMaps maps = makeHeadSkinDetail();
        model.albedoMap = std::make_shared<const Image>(std::move(maps.albedo));
        model.normalMap = std::make_shared<const Image>(std::move(maps.normal));
    }
    return model;
}

} // namespace skinlab::renderer
