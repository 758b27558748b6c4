// Built-in procedural geometry (renderer/scene/builtin_geometry.h): mesh invariants shared by every model,
// and the physical property each built-in scene exists for (halo depth gap, bleed albedo regions, ear
// thickness, head landmarks).
#include "common/error.h"
#include "renderer/scene/builtin_geometry.h"
#include "renderer/scene/skin_detail.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <map>
#include <numbers>
#include <string>

namespace skinlab::renderer {
namespace {

const MeshMaterial& materialNamed(const Model& model, const std::string& name) {
    for (const MeshMaterial& material : model.materials) {
        if (material.name == name) return material;
    }
    throw std::runtime_error("no material " + name);
}

std::uint32_t materialIndex(const Model& model, const std::string& name) {
    for (std::size_t i = 0; i < model.materials.size(); ++i) {
        if (model.materials[i].name == name) return static_cast<std::uint32_t>(i);
    }
    throw std::runtime_error("no material " + name);
}

// Calls f(vertex) for every vertex referenced by the parts of one material.
void forEachVertexOf(const Model& model, std::uint32_t material, const std::function<void(const Vertex&)>& f) {
    for (const SubMesh& part : model.parts) {
        if (part.material != material) continue;
        for (std::uint32_t i = part.firstIndex; i < part.firstIndex + part.indexCount; ++i) {
            f(model.vertices[model.indices[i]]);
        }
    }
}

// Invariants every Model must satisfy (mesh.h): indices in range, parts tiling the index buffer, unit normals,
// unit tangents orthogonal to them with w = ±1, UVs in [0, 1], bounds equal to the referenced vertices, no
// degenerate triangles, triangles wound counter-clockwise around their vertex normals.
void expectValidModel(const Model& model) {
    ASSERT_FALSE(model.indices.empty());
    ASSERT_EQ(model.indices.size() % 3, 0u);
    for (std::uint32_t index : model.indices) ASSERT_LT(index, model.vertices.size());
    std::uint32_t next = 0;
    for (const SubMesh& part : model.parts) {
        EXPECT_EQ(part.firstIndex, next);
        EXPECT_EQ(part.indexCount % 3, 0u);
        EXPECT_LT(part.material, model.materials.size());
        next = part.firstIndex + part.indexCount;
    }
    EXPECT_EQ(next, model.indices.size()) << "parts must cover every index";

    glm::vec3 lowest(1e30f);
    glm::vec3 highest(-1e30f);
    for (std::uint32_t index : model.indices) {
        lowest = glm::min(lowest, model.vertices[index].position);
        highest = glm::max(highest, model.vertices[index].position);
    }
    EXPECT_EQ(model.boundsMin, lowest);
    EXPECT_EQ(model.boundsMax, highest);

    int badNormal = 0;
    int badTangent = 0;
    int badUv = 0;
    for (const Vertex& v : model.vertices) {
        // 1e-4: float normalisation leaves errors of a few ulp; anything larger is a missing normalize().
        if (std::abs(glm::length(v.normal) - 1.0f) > 1e-4f) ++badNormal;
        const glm::vec3 t(v.tangent);
        if (std::abs(glm::length(t) - 1.0f) > 1e-4f || std::abs(glm::dot(t, v.normal)) > 1e-4f ||
            std::abs(std::abs(v.tangent.w) - 1.0f) != 0.0f) {
            ++badTangent;
        }
        if (v.uv.x < 0.0f || v.uv.x > 1.0f || v.uv.y < 0.0f || v.uv.y > 1.0f) ++badUv;
    }
    EXPECT_EQ(badNormal, 0) << "vertex normals must be unit length";
    EXPECT_EQ(badTangent, 0) << "tangents must be unit, orthogonal to the normal, w = ±1";
    EXPECT_EQ(badUv, 0) << "UVs must lie in [0, 1]";

    int degenerate = 0;
    int wrongWinding = 0;
    for (std::size_t t = 0; t < model.indices.size(); t += 3) {
        const Vertex& a = model.vertices[model.indices[t]];
        const Vertex& b = model.vertices[model.indices[t + 1]];
        const Vertex& c = model.vertices[model.indices[t + 2]];
        const glm::vec3 cross = glm::cross(b.position - a.position, c.position - a.position);
        if (glm::length(cross) <= 0.0f) {
            ++degenerate;
            continue;
        }
        if (glm::dot(cross, a.normal + b.normal + c.normal) <= 0.0f) ++wrongWinding;
    }
    EXPECT_EQ(degenerate, 0);
    EXPECT_EQ(wrongWinding, 0) << "triangles must be counter-clockwise seen from their normals' side";
}

// Edges of the triangles of one material with positions welded (bit-identical positions are one point): a
// closed surface uses every edge exactly twice.
int countOpenEdges(const Model& model, std::uint32_t material) {
    const auto key = [](const glm::vec3& p) {
        const glm::vec3 canonical = p + glm::vec3(0.0f); // -0 → +0
        std::array<std::uint32_t, 3> bits{};
        std::memcpy(bits.data(), &canonical, sizeof(canonical));
        return bits;
    };
    std::map<std::array<std::uint32_t, 3>, int> ids;
    const auto id = [&](const glm::vec3& p) { return ids.emplace(key(p), static_cast<int>(ids.size())).first->second; };
    std::map<std::pair<int, int>, int> edges;
    for (const SubMesh& part : model.parts) {
        if (part.material != material) continue;
        for (std::uint32_t t = part.firstIndex; t < part.firstIndex + part.indexCount; t += 3) {
            const int corner[3] = {id(model.vertices[model.indices[t]].position),
                                   id(model.vertices[model.indices[t + 1]].position),
                                   id(model.vertices[model.indices[t + 2]].position)};
            for (int k = 0; k < 3; ++k) {
                const int a = corner[k];
                const int b = corner[(k + 1) % 3];
                ++edges[{std::min(a, b), std::max(a, b)}];
            }
        }
    }
    int open = 0;
    for (const auto& [edge, uses] : edges) {
        if (uses != 2) ++open;
    }
    return open;
}

// Signed volume of the triangles of one part (divergence theorem); positive for outward-facing closed surfaces.
double signedVolume(const Model& model, const SubMesh& part) {
    double volume = 0.0;
    for (std::uint32_t t = part.firstIndex; t < part.firstIndex + part.indexCount; t += 3) {
        const glm::dvec3 a(model.vertices[model.indices[t]].position);
        const glm::dvec3 b(model.vertices[model.indices[t + 1]].position);
        const glm::dvec3 c(model.vertices[model.indices[t + 2]].position);
        volume += glm::dot(a, glm::cross(b, c)) / 6.0;
    }
    return volume;
}

double partArea(const Model& model, std::uint32_t material) {
    double area = 0.0;
    for (const SubMesh& part : model.parts) {
        if (part.material != material) continue;
        for (std::uint32_t t = part.firstIndex; t < part.firstIndex + part.indexCount; t += 3) {
            const glm::dvec3 a(model.vertices[model.indices[t]].position);
            const glm::dvec3 b(model.vertices[model.indices[t + 1]].position);
            const glm::dvec3 c(model.vertices[model.indices[t + 2]].position);
            area += 0.5 * glm::length(glm::cross(b - a, c - a));
        }
    }
    return area;
}

// --- builtin:halo -------------------------------------------------------------------------------------------

// A length parameter as a test name: 0.5f -> "0_5mm", 200.0f -> "200mm".
std::string millimetresName(const ::testing::TestParamInfo<float>& param) {
    char text[32];
    std::snprintf(text, sizeof text, "%gmm", static_cast<double>(param.param));
    std::string name = text;
    for (char& c : name)
        if (c == '.') c = '_';
    return name;
}

class HaloDepthGap : public ::testing::TestWithParam<float> {};

TEST_P(HaloDepthGap, BackdropSitsExactlyTheGapBehindTheSphere) {
    const float gap = GetParam();
    const Model model = makeHaloScene(gap);
    expectValidModel(model);
    float sphereBack = 1e30f;
    float sphereFront = -1e30f;
    forEachVertexOf(model, materialIndex(model, "skin"), [&](const Vertex& v) {
        sphereBack = std::min(sphereBack, v.position.z);
        sphereFront = std::max(sphereFront, v.position.z);
    });
    float backdropMin = 1e30f;
    float backdropMax = -1e30f;
    forEachVertexOf(model, materialIndex(model, "backdrop"), [&](const Vertex& v) {
        backdropMin = std::min(backdropMin, v.position.z);
        backdropMax = std::max(backdropMax, v.position.z);
        EXPECT_EQ(v.normal, glm::vec3(0.0f, 0.0f, 1.0f)) << "the backdrop faces the camera (+Z)";
    });
    EXPECT_EQ(backdropMin, backdropMax) << "the backdrop is a plane of constant depth";
    // 1e-4 relative: float rounding of z = -(40 + gap) and of 40·cos(0); the grid has a vertex exactly on the
    // sphere's back pole direction (-Z).
    EXPECT_NEAR(sphereBack - backdropMax, gap, 1e-4f * (kHaloSphereRadiusMm + gap));
    EXPECT_NEAR(sphereFront, kHaloSphereRadiusMm, 1e-4f);
    EXPECT_NEAR(model.boundsMax.x - model.boundsMin.x, kHaloBackdropSizeMm, 1e-3f);
}

INSTANTIATE_TEST_SUITE_P(Gaps, HaloDepthGap, ::testing::Values(1.0f, 50.0f, 200.0f, 2000.0f), millimetresName);

TEST(HaloScene, SphereIsClosedRoundAndSkinBackdropIsNot) {
    const Model model = makeHaloScene(200.0f);
    EXPECT_TRUE(materialNamed(model, "skin").skin);
    EXPECT_FALSE(materialNamed(model, "backdrop").skin);
    const std::uint32_t skin = materialIndex(model, "skin");
    EXPECT_EQ(countOpenEdges(model, skin), 0) << "the sphere must be watertight";
    forEachVertexOf(model, skin, [](const Vertex& v) {
        EXPECT_NEAR(glm::length(v.position), kHaloSphereRadiusMm, 1e-4f);
        // Smooth normals of a sphere point radially; 1e-3 allows for the angle-weighted face average.
        EXPECT_GT(glm::dot(v.normal, glm::normalize(v.position)), 1.0f - 1e-3f);
    });
    for (const SubMesh& part : model.parts) {
        if (part.material != skin) continue;
        const double exact = 4.0 / 3.0 * std::numbers::pi * std::pow(kHaloSphereRadiusMm, 3.0);
        // An inscribed polyhedron of 128 × 64 cells loses ~0.1% of the volume; 0.5% catches a wrong winding
        // (negative volume) or a missing band of cells.
        EXPECT_NEAR(signedVolume(model, part) / exact, 1.0, 5e-3);
    }
}

TEST(HaloScene, RejectsGapsOutOfRangeWithTheKeyNamed) {
    try {
        makeHaloScene(0.0f);
        FAIL() << "expected InputError";
    } catch (const InputError& error) {
        EXPECT_STREQ(error.what(), "builtin:halo: depth_gap_mm: 0 is out of range (0, 10000]");
    }
    EXPECT_THROW(makeHaloScene(-5.0f), InputError);
    EXPECT_THROW(makeHaloScene(20000.0f), InputError);
    EXPECT_THROW(makeHaloScene(std::nanf("")), InputError);
}

// --- builtin:bleed ------------------------------------------------------------------------------------------

TEST(BleedScene, PaintSquaresHaveTheirAlbedoAndExactExtents) {
    const Model model = makeBleedScene();
    expectValidModel(model);
    EXPECT_TRUE(materialNamed(model, "skin").skin);
    EXPECT_FALSE(materialNamed(model, "paint-dark").skin);
    EXPECT_FALSE(materialNamed(model, "paint-bright").skin);
    EXPECT_EQ(materialNamed(model, "paint-dark").albedo, kBleedDarkAlbedo);
    EXPECT_EQ(materialNamed(model, "paint-bright").albedo, kBleedBrightAlbedo);
    // "Very different albedo": the dark paint reflects < 5% and the bright one has a channel > skin's.
    const glm::vec3 skinAlbedo = materialNamed(model, "skin").albedo;
    EXPECT_LT(kBleedDarkAlbedo.g * 10.0f, skinAlbedo.g);
    EXPECT_GT(kBleedBrightAlbedo.b, 2.0f * skinAlbedo.b);

    const float halfSquare = 0.5f * kBleedSquareSizeMm;
    const struct {
        const char* name;
        float centreX;
    } squares[] = {{"paint-dark", -kBleedSquareOffsetMm}, {"paint-bright", kBleedSquareOffsetMm}};
    for (const auto& square : squares) {
        glm::vec2 lowest(1e30f);
        glm::vec2 highest(-1e30f);
        forEachVertexOf(model, materialIndex(model, square.name), [&](const Vertex& v) {
            lowest = glm::min(lowest, glm::vec2(v.position));
            highest = glm::max(highest, glm::vec2(v.position));
        });
        EXPECT_NEAR(lowest.x, square.centreX - halfSquare, 1e-4f) << square.name;
        EXPECT_NEAR(highest.x, square.centreX + halfSquare, 1e-4f) << square.name;
        EXPECT_NEAR(lowest.y, -halfSquare, 1e-4f) << square.name;
        EXPECT_NEAR(highest.y, halfSquare, 1e-4f) << square.name;
        // Area within float rounding (1e-3 relative): the square is fully tiled, nothing else is in the part.
        EXPECT_NEAR(partArea(model, materialIndex(model, square.name)) / (kBleedSquareSizeMm * kBleedSquareSizeMm), 1.0,
                    1e-3);
    }
    const double patch = kBleedPatchSizeMm * kBleedPatchSizeMm;
    EXPECT_NEAR(partArea(model, materialIndex(model, "skin")) / (patch - 2.0 * kBleedSquareSizeMm * kBleedSquareSizeMm),
                1.0, 1e-3);
}

TEST(BleedScene, BoundariesAreSharpAndAtOneDepth) {
    const Model model = makeBleedScene();
    // Same depth everywhere: no depth discontinuity for a depth-aware filter to find.
    EXPECT_EQ(model.boundsMin.z, 0.0f);
    EXPECT_EQ(model.boundsMax.z, 0.0f);
    // No vertex is shared between parts: attributes (material, skin mask) step exactly at the boundary.
    std::map<std::uint32_t, std::uint32_t> owner;
    int shared = 0;
    for (const SubMesh& part : model.parts) {
        for (std::uint32_t i = part.firstIndex; i < part.firstIndex + part.indexCount; ++i) {
            const auto [it, inserted] = owner.emplace(model.indices[i], part.material);
            if (!inserted && it->second != part.material) ++shared;
        }
    }
    EXPECT_EQ(shared, 0);
    // ... yet the parts meet: a paint corner has a skin vertex at the very same position (no gap, no overlap).
    int skinAtCorner = 0;
    forEachVertexOf(model, materialIndex(model, "skin"), [&](const Vertex& v) {
        if (v.position ==
            glm::vec3(-kBleedSquareOffsetMm - 0.5f * kBleedSquareSizeMm, 0.5f * kBleedSquareSizeMm, 0.0f)) {
            ++skinAtCorner;
        }
    });
    EXPECT_GT(skinAtCorner, 0);
}

// --- builtin:ear --------------------------------------------------------------------------------------------

class EarThickness : public ::testing::TestWithParam<float> {};

TEST_P(EarThickness, SlabIsExactlyAsThickAsAsked) {
    const float thickness = GetParam();
    const Model model = makeEarScene(thickness);
    expectValidModel(model);
    EXPECT_TRUE(materialNamed(model, "skin").skin);
    // The two faces are concentric cylinders around the bend axis (x = 0, z = R): front radius R − t/2, back
    // R + t/2; the rim lies between. So the distance to the axis spans exactly the thickness.
    float nearest = 1e30f;
    float farthest = -1e30f;
    for (const Vertex& v : model.vertices) {
        const float distance = glm::length(glm::vec2(v.position.x, v.position.z - kEarBendRadiusMm));
        nearest = std::min(nearest, distance);
        farthest = std::max(farthest, distance);
    }
    // 2e-5 mm: float rounding of positions ~30 mm from the axis.
    EXPECT_NEAR(farthest - nearest, thickness, 2e-5f * kEarBendRadiusMm);
    EXPECT_NEAR(nearest, kEarBendRadiusMm - 0.5f * thickness, 2e-5f * kEarBendRadiusMm);
    // Front-centre point on the viewing axis: the slab is crossed by the view ray through the origin from
    // z = +t/2 to −t/2.
    EXPECT_NEAR(model.boundsMax.y - model.boundsMin.y, kEarHeightMm, 1e-3f);
    EXPECT_EQ(countOpenEdges(model, 0), 0) << "the fin must be watertight";
    EXPECT_GT(signedVolume(model, model.parts[0]), 0.0);
}

INSTANTIATE_TEST_SUITE_P(Thicknesses, EarThickness, ::testing::Values(0.5f, 2.5f, 6.0f), millimetresName);

TEST(EarScene, ConcaveSideFacesTheViewer) {
    const Model model = makeEarScene(2.5f);
    // The rims bend towards +Z (the viewer); the centre is the deepest point of the front face.
    EXPECT_NEAR(model.boundsMin.z, -1.25f, 1e-4f);
    EXPECT_GT(model.boundsMax.z, 5.0f);
    EXPECT_THROW(makeEarScene(0.0f), InputError);
    try {
        makeEarScene(25.0f);
        FAIL() << "expected InputError";
    } catch (const InputError& error) {
        EXPECT_STREQ(error.what(), "builtin:ear: thickness_mm: 25 is out of range (0, 20]");
    }
}

// --- builtin:head -------------------------------------------------------------------------------------------

TEST(HeadScene, SizeTriangleCountAndMaterials) {
    const Model model = makeHeadScene(false);
    expectValidModel(model);
    const std::size_t triangles = model.indices.size() / 3;
    EXPECT_GE(triangles, 20000u);
    EXPECT_LE(triangles, 60000u);
    EXPECT_TRUE(materialNamed(model, "skin").skin);
    EXPECT_FALSE(materialNamed(model, "eye").skin);
    // Left-right symmetric: the ears are mirror images.
    EXPECT_NEAR(model.boundsMin.x, -model.boundsMax.x, 1e-3f);
    EXPECT_NEAR(model.boundsMax.x, kHeadEarOuterX, 1.0f);
    EXPECT_NEAR(model.boundsMax.y, kHeadVertexY, 1.0f);
    EXPECT_NEAR(model.boundsMin.y, kHeadNeckBottomY, 1e-3f);
    EXPECT_NEAR(model.boundsMax.z, kHeadNoseTipZ, 1.0f);
}

TEST(HeadScene, HeadSurfaceIsWatertightAndFeaturesSitWhereDocumented) {
    const Model model = makeHeadScene(false);
    // The first part is the skull/face surface.
    const SubMesh& head = model.parts.front();
    EXPECT_EQ(countOpenEdges(Model{model.vertices, model.indices, {head}, model.materials, {}, {}}, head.material), 0);
    EXPECT_GT(signedVolume(model, head), 0.0);
    float chin = 1e30f;
    float top = -1e30f;
    glm::vec3 noseTip(0.0f, 0.0f, -1e30f);
    for (std::uint32_t i = head.firstIndex; i < head.firstIndex + head.indexCount; ++i) {
        const glm::vec3& p = model.vertices[model.indices[i]].position;
        if (p.z > 30.0f && std::abs(p.x) < 20.0f) chin = std::min(chin, p.y);
        top = std::max(top, p.y);
        if (p.z > noseTip.z) noseTip = p;
    }
    // ±1 mm: the landmarks are measured on this mesh and rounded in the header.
    EXPECT_NEAR(chin, kHeadChinY, 1.0f);
    EXPECT_NEAR(top, kHeadVertexY, 1.0f);
    EXPECT_NEAR(noseTip.z, kHeadNoseTipZ, 1.0f);
    EXPECT_NEAR(noseTip.x, 0.0f, 1.0f) << "the nose is on the midline";
    EXPECT_LT(noseTip.y, 0.0f) << "the nose tip is below the eyes";
    EXPECT_GT(noseTip.y, chin + 60.0f) << "... and well above the chin";
    // Menton–vertex height of a typical adult male (≈ 230 mm), within 10 mm.
    EXPECT_NEAR(top - chin, 230.0f, 10.0f);
    // The nose protrudes: 15+ mm in front of the face 25 mm to either side of it (adult nasal protrusion,
    // subnasale–pronasale, is about 20 mm; the cheeks beside the nose sit a little behind the subnasale).
    float cheekFront = -1e30f;
    for (const Vertex& v : model.vertices) {
        if (std::abs(std::abs(v.position.x) - 25.0f) < 2.0f && std::abs(v.position.y - noseTip.y) < 2.0f) {
            cheekFront = std::max(cheekFront, v.position.z);
        }
    }
    EXPECT_GT(noseTip.z - cheekFront, 15.0f);
}

TEST(HeadScene, LipsAreRedderAndBrowsDarker) {
    const Model model = makeHeadScene(false);
    const SubMesh& head = model.parts.front();
    int lips = 0;
    int brows = 0;
    int elsewhereTinted = 0;
    for (std::uint32_t i = head.firstIndex; i < head.firstIndex + head.indexCount; ++i) {
        const Vertex& v = model.vertices[model.indices[i]];
        const glm::vec3& p = v.position;
        const bool nearMouth = p.z > 40.0f && std::abs(p.x) < 25.0f && std::abs(p.y + 66.0f) < 13.0f;
        const bool nearBrows =
            p.z > 40.0f && std::abs(p.x) > 10.0f && std::abs(p.x) < 55.0f && std::abs(p.y - 21.0f) < 7.0f;
        if (nearMouth && v.color.r > 1.0f && v.color.g < 0.7f) ++lips;
        if (nearBrows && v.color.r < 0.4f && v.color.g < 0.4f) ++brows;
        if (!nearMouth && !nearBrows && v.color != glm::vec3(1.0f)) ++elsewhereTinted;
    }
    EXPECT_GT(lips, 20);
    EXPECT_GT(brows, 20);
    EXPECT_EQ(elsewhereTinted, 0) << "albedo tints only on lips and brows";
}

TEST(HeadScene, EarsProtrudeAtTheSidesAtEarHeight) {
    const Model model = makeHeadScene(false);
    // Parts after the head surface: ear, ear, eye, eye, neck side, neck cap.
    ASSERT_GE(model.parts.size(), 3u);
    for (int ear : {1, 2}) {
        const SubMesh& part = model.parts[static_cast<std::size_t>(ear)];
        glm::vec3 lowest(1e30f);
        glm::vec3 highest(-1e30f);
        for (std::uint32_t i = part.firstIndex; i < part.firstIndex + part.indexCount; ++i) {
            lowest = glm::min(lowest, model.vertices[model.indices[i]].position);
            highest = glm::max(highest, model.vertices[model.indices[i]].position);
        }
        const float outer = std::max(std::abs(lowest.x), std::abs(highest.x));
        EXPECT_NEAR(outer, kHeadEarOuterX, 1.0f);
        EXPECT_GT(highest.y - lowest.y, 55.0f) << "an adult ear is about 60 mm long";
        EXPECT_LT(lowest.y, -30.0f); // from about the nose base ...
        EXPECT_GT(highest.y, 10.0f); // ... to about the brows
        EXPECT_EQ(countOpenEdges(Model{model.vertices, model.indices, {part}, model.materials, {}, {}}, part.material),
                  0);
        EXPECT_GT(signedVolume(model, part), 0.0) << "mirrored ear must still face outwards";
    }
}

TEST(BuiltinGeometry, IsDeterministic) {
    const Model first = makeHeadScene(false);
    const Model second = makeHeadScene(false);
    ASSERT_EQ(first.vertices.size(), second.vertices.size());
    EXPECT_EQ(0, std::memcmp(first.vertices.data(), second.vertices.data(), first.vertices.size() * sizeof(Vertex)));
    EXPECT_EQ(first.indices, second.indices);
}

// --- builtin:head's skin detail (skin_detail.h) -------------------------------------------------------------

TEST(HeadSkinDetail, MapsAreDeterministicUnitNormalsWithDetailAndNoSeam) {
    // Smaller than the built-in 2048 × 1024 to stay quick; the features are functions of the surface point in mm,
    // so the statistics are those of the full maps, sampled more coarsely.
    const SkinDetailMaps maps = makeHeadSkinDetail(1024, 512);
    const SkinDetailMaps again = makeHeadSkinDetail(1024, 512);
    ASSERT_EQ(maps.normal.width, 1024);
    ASSERT_EQ(maps.albedo.height, 512);
    EXPECT_EQ(maps.normal.pixels, again.normal.pixels);
    EXPECT_EQ(maps.albedo.pixels, again.albedo.pixels);
    double albedoSum = 0.0, tiltSum = 0.0;
    int tilted = 0, count = 0;
    for (int y = 0; y < 512; ++y)
        for (int x = 0; x < 1024; ++x) {
            const glm::vec4 n = maps.normal.texel(x, y);
            const glm::vec3 normal = glm::vec3(n) * 2.0f - 1.0f;
            ASSERT_NEAR(glm::length(normal), 1.0f, 1e-4f) << x << ", " << y;
            ASSERT_GT(normal.z, 0.0f);
            if (y == 0) {
                // Row 0 (the crown pole, sampled by the eyes) is flat with albedo 1.
                EXPECT_EQ(glm::vec3(n), glm::vec3(0.5f, 0.5f, 1.0f));
                EXPECT_EQ(glm::vec3(maps.albedo.texel(x, y)), glm::vec3(1.0f));
                continue;
            }
            const glm::vec3 a(maps.albedo.texel(x, y));
            ASSERT_GT(a.g, 0.2f);
            ASSERT_LT(a.r, 1.5f);
            albedoSum += (a.r + a.g + a.b) / 3.0;
            const double tilt = std::sqrt(normal.x * normal.x + normal.y * normal.y);
            tiltSum += tilt;
            tilted += tilt > 0.1;
            ++count;
        }
    const double albedoMean = albedoSum / count;
    const double tiltMean = tiltSum / count;
    std::printf(
        "head skin detail 1024×512: albedo multiplier mean %.4f; normal tilt mean %.4f, %.1f %% of texels tilted > "
        "0.1\n",
        albedoMean, tiltMean, 100.0 * tilted / count);
    EXPECT_NEAR(albedoMean, 1.0, 0.05); // the map varies the skin albedo, it does not change its tone
    // Pores and lines: the normal map is not flat (a flat map gives 0 and 0; measured at this size: 0.023 and 1.1 %).
    EXPECT_GT(tiltMean, 0.01);
    EXPECT_GT(tilted, count / 200);
    // No seam at u = 0 = 1 (the front of the face): neighbours across the seam differ no more than neighbours
    // inside the chart do, on average over the face rows.
    double across = 0.0, inside = 0.0;
    for (int y = 200; y < 330; ++y) {
        across += glm::length(glm::vec3(maps.albedo.texel(0, y)) - glm::vec3(maps.albedo.texel(1023, y)));
        inside += glm::length(glm::vec3(maps.albedo.texel(1, y)) - glm::vec3(maps.albedo.texel(0, y)));
    }
    EXPECT_LT(across, 2.0 * inside + 1e-3);
}

TEST(HeadSkinDetail, TheHeadBringsTheMapsUnlessAskedForTheSmoothHead) {
    const Model detailed = makeHeadScene();
    ASSERT_TRUE(detailed.albedoMap && detailed.normalMap);
    EXPECT_EQ(detailed.normalMap->width, kHeadDetailWidth);
    EXPECT_EQ(detailed.normalMap->height, kHeadDetailHeight);
    const Model smooth = makeHeadScene(false);
    EXPECT_FALSE(smooth.albedoMap || smooth.normalMap);
    // The same mesh either way.
    ASSERT_EQ(detailed.vertices.size(), smooth.vertices.size());
    EXPECT_EQ(0,
              std::memcmp(detailed.vertices.data(), smooth.vertices.data(), smooth.vertices.size() * sizeof(Vertex)));
    // The eyes sample the flat row 0 of the maps.
    const SubMesh& eye = detailed.parts[3];
    ASSERT_EQ(detailed.materials[eye.material].name, "eye");
    for (std::uint32_t i = eye.firstIndex; i < eye.firstIndex + eye.indexCount; ++i)
        ASSERT_LT(detailed.vertices[detailed.indices[i]].uv.y, 1.0f / static_cast<float>(kHeadDetailHeight));
}

} // namespace
} // namespace skinlab::renderer
