// Tessellation of skin parts and point sampling for the object-space reference.
#include "common/error.h"
#include "renderer/reference/surface_samples.h"
#include "renderer/reference/tessellation.h"
#include "renderer/scene/builtin_geometry.h"
#include "test_models.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <map>
#include <set>

using namespace skinlab::renderer;
using namespace skinlab::renderer::reference;

namespace {
// Every edge of a part's triangles is used by one (boundary) or two (interior) triangles: the mesh is conforming.
std::map<std::pair<std::uint32_t, std::uint32_t>, int> edgeUses(const Model& model, const SubMesh& part) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
    for (std::uint32_t i = part.firstIndex; i < part.firstIndex + part.indexCount; i += 3)
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t a = model.indices[i + k], b = model.indices[i + (k + 1) % 3];
            ++uses[{std::min(a, b), std::max(a, b)}];
        }
    return uses;
}

// Vertex count the former uniform scheme (every skin triangle 1 → 4 each round until the longest skin edge fits)
// reaches: V' = V + E, E' = 2E + 3T, T' = 4T per round, each round halving every edge.
std::size_t uniformSchemeVertices(const Model& model, float targetEdgeMm, float mmPerUnit) {
    std::size_t vertices = model.vertices.size(), edges = 0, triangles = 0;
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> allEdges;
    for (const auto& part : model.parts) {
        if (!model.materials[part.material].skin) continue;
        for (const auto& [edge, count] : edgeUses(model, part)) allEdges[edge] += count;
        triangles += part.indexCount / 3;
    }
    edges = allEdges.size();
    for (float longest = longestSkinEdgeMm(model, mmPerUnit); longest > targetEdgeMm; longest *= 0.5f) {
        vertices += edges;
        edges = 2 * edges + 3 * triangles;
        triangles *= 4;
    }
    return vertices;
}

// One skin part made of two disconnected pieces: a 5 mm square as a 10 × 10 grid of 0.5 mm cells (200 small
// triangles) at x ∈ [-30, -25], and a 20 mm square of two triangles at x ∈ [0, 20].
Model makeMixedSizes() {
    Model model;
    const auto addVertex = [&](float x, float y) {
        Vertex v;
        v.position = glm::vec3(x, y, 0.0f);
        model.vertices.push_back(v);
        return static_cast<std::uint32_t>(model.vertices.size() - 1);
    };
    for (int j = 0; j <= 10; ++j)
        for (int i = 0; i <= 10; ++i) addVertex(-30.0f + 0.5f * float(i), 0.5f * float(j));
    for (int j = 0; j < 10; ++j)
        for (int i = 0; i < 10; ++i) {
            const std::uint32_t v = static_cast<std::uint32_t>(j * 11 + i);
            model.indices.insert(model.indices.end(), {v, v + 1, v + 12, v, v + 12, v + 11});
        }
    const std::uint32_t a = addVertex(0, 0), b = addVertex(20, 0), c = addVertex(20, 20), d = addVertex(0, 20);
    model.indices.insert(model.indices.end(), {a, b, c, a, c, d});
    model.parts.push_back({0, static_cast<std::uint32_t>(model.indices.size()), 0});
    model.materials.push_back({"skin", glm::vec3(1.0f), true, 0.6f, 1.0f});
    model.computeBounds();
    return model;
}

double skinArea(const SurfaceSamples& samples) {
    double area = 0.0;
    for (std::size_t i = 0; i < samples.size(); ++i)
        if (samples.skin[i]) area += samples.areaMm2[i];
    return area;
}
} // namespace

TEST(Tessellation, SplitsUntilTheTargetEdgeAndStaysConforming) {
    const Model square = test_models::makeSquare(10.0f);
    TessellationStatistics statistics;
    const Model fine = tessellateSkin(square, 1.0f, 1.0f, &statistics);
    // Diagonal 14.14 mm → 4 rounds (14.14 / 16 = 0.88 mm ≤ 1 mm; 3 rounds leave 1.77 mm).
    EXPECT_EQ(statistics.rounds, 4);
    EXPECT_LE(longestSkinEdgeMm(fine, 1.0f), 1.0f);
    EXPECT_NEAR(statistics.longestSkinEdgeMm, 10.0f * std::sqrt(2.0f) / 16.0f, 1e-4f);
    EXPECT_EQ(statistics.skinTriangles, 2u * 256u);
    EXPECT_EQ(fine.vertices.size(), 17u * 17u); // a 16 × 16 grid of cells
    // Original vertices keep their indices and positions.
    for (std::size_t i = 0; i < square.vertices.size(); ++i)
        EXPECT_EQ(fine.vertices[i].position, square.vertices[i].position);
    int boundary = 0;
    for (const auto& [edge, count] : edgeUses(fine, fine.parts[0])) {
        EXPECT_LE(count, 2);
        if (count == 1) ++boundary;
    }
    EXPECT_EQ(boundary, 4 * 16); // only the square's outline is open
}

TEST(Tessellation, SplitsOnlyLongTrianglesOfAMixedMesh) {
    const Model mixed = makeMixedSizes();
    TessellationStatistics statistics;
    const Model fine = tessellateSkin(mixed, 2.0f, 1.0f, &statistics);
    EXPECT_LE(longestSkinEdgeMm(fine, 1.0f), 2.0f);
    // The 200 small triangles (0.71 mm diagonals) are in the output unchanged, with the same vertex indices.
    std::set<std::array<std::uint32_t, 3>> triangles;
    for (std::size_t i = 0; i + 2 < fine.indices.size(); i += 3)
        triangles.insert({fine.indices[i], fine.indices[i + 1], fine.indices[i + 2]});
    for (std::size_t i = 0; i < 600; i += 3)
        EXPECT_TRUE(triangles.count({mixed.indices[i], mixed.indices[i + 1], mixed.indices[i + 2]}))
            << "triangle " << i / 3;
    for (std::size_t i = 0; i < mixed.vertices.size(); ++i)
        EXPECT_EQ(fine.vertices[i].position, mixed.vertices[i].position);
    // Conforming: every edge used at most twice; the open edges are the two outlines (40 small + 4 × 2^k large).
    int boundary = 0;
    for (const auto& [edge, count] : edgeUses(fine, fine.parts[0])) {
        EXPECT_LE(count, 2);
        if (count == 1) ++boundary;
    }
    const std::size_t uniform = uniformSchemeVertices(mixed, 2.0f, 1.0f);
    std::printf("mixed mesh at 2 mm: %zu vertices (%d rounds, %zu boundary edges); uniform scheme: %zu\n",
                fine.vertices.size(), statistics.rounds, std::size_t(boundary), uniform);
    EXPECT_EQ(boundary, 40 + 4 * 16);              // the 20 mm square's sides end at 1.25 mm, like the uniform scheme's
    EXPECT_LT(fine.vertices.size() * 20, uniform); // far below: only the large square is refined
    // The 20 mm square is refined like the uniform scheme does it (17 × 17 grid), the small grid not at all.
    EXPECT_EQ(fine.vertices.size(), 121u + 17u * 17u);
}

TEST(Tessellation, BuiltinHeadNeedsFarFewerVerticesThanUniformRounds) {
    const Model head = makeHeadScene(false);
    TessellationStatistics statistics;
    const Model fine = tessellateSkin(head, 2.0f, 1.0f, &statistics);
    const std::size_t uniform = uniformSchemeVertices(head, 2.0f, 1.0f);
    std::printf("builtin:head at 2 mm: %zu -> %zu vertices in %d rounds (longest skin edge %.3f mm); uniform "
                "scheme: %zu\n",
                head.vertices.size(), fine.vertices.size(), statistics.rounds, statistics.longestSkinEdgeMm, uniform);
    EXPECT_LE(statistics.longestSkinEdgeMm, 2.0f);
    EXPECT_LT(fine.vertices.size() * 5, uniform);
    for (const auto& part : fine.parts) {
        if (!fine.materials[part.material].skin) continue;
        for (const auto& [edge, count] : edgeUses(fine, part)) ASSERT_LE(count, 2);
    }
}

TEST(Tessellation, ScalesWithMillimetresPerUnitAndKeepsNonSkinParts) {
    const Model halo = makeHaloScene(200.0f);
    const Model fine = tessellateSkin(halo, 1.0f, 1.0f);
    // The backdrop (non-skin) is untouched: same index count; the sphere is refined.
    ASSERT_EQ(fine.parts.size(), halo.parts.size());
    for (std::size_t p = 0; p < halo.parts.size(); ++p) {
        if (halo.materials[halo.parts[p].material].skin) EXPECT_GT(fine.parts[p].indexCount, halo.parts[p].indexCount);
        else EXPECT_EQ(fine.parts[p].indexCount, halo.parts[p].indexCount);
    }
    EXPECT_LE(longestSkinEdgeMm(fine, 1.0f), 1.0f);
    // The same square in centimetre units (0.1 unit per mm): 1 unit = 10 mm, so 1 mm needs the same 4 rounds.
    TessellationStatistics statistics;
    tessellateSkin(test_models::makeSquare(1.0f), 1.0f, 10.0f, &statistics);
    EXPECT_EQ(statistics.rounds, 4);
}

TEST(Tessellation, RefusesTargetsThatExplodeTheMesh) {
    try {
        tessellateSkin(test_models::makeSquare(1000.0f), 0.01f, 1.0f, nullptr, 100000);
        FAIL() << "no exception";
    } catch (const skinlab::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("reference: edge_mm: 0.010000 mm needs more than 100000 vertices"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_THROW(tessellateSkin(test_models::makeSquare(1.0f), 0.0f, 1.0f), skinlab::InputError);
}

TEST(SurfaceSamples, AreasSumToTheSkinSurface) {
    const Model fine = tessellateSkin(test_models::makeSquare(10.0f), 1.0f, 1.0f);
    const SurfaceSamples samples = gatherSurfaceSamples(fine, 1.0f);
    ASSERT_EQ(samples.size(), fine.vertices.size());
    EXPECT_NEAR(skinArea(samples), 100.0, 1e-3);
    // Millimetres per unit scales areas by its square.
    EXPECT_NEAR(skinArea(gatherSurfaceSamples(fine, 2.0f)), 400.0, 4e-3);

    // builtin:bleed: skin area = patch − two paint squares; paint samples are not skin.
    const Model bleed = makeBleedScene();
    const SurfaceSamples bleedSamples = gatherSurfaceSamples(bleed, 1.0f);
    const double expected = kBleedPatchSizeMm * kBleedPatchSizeMm - 2.0 * kBleedSquareSizeMm * kBleedSquareSizeMm;
    EXPECT_NEAR(skinArea(bleedSamples), expected, 1e-4 * expected);
    int paint = 0;
    for (std::size_t i = 0; i < bleedSamples.size(); ++i)
        if (!bleedSamples.skin[i]) {
            ++paint;
            EXPECT_LT(bleedSamples.albedo[i].r, 0.1f); // both paints have red albedo 0.02 / 0.05
        }
    EXPECT_GT(paint, 0);
}
