// Tessellation of skin parts and point sampling for the object-space reference.
#include "common/error.h"
#include "renderer/reference/surface_samples.h"
#include "renderer/reference/tessellation.h"
#include "renderer/scene/builtin_geometry.h"
#include "test_models.h"

#include <gtest/gtest.h>

#include <map>

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
    EXPECT_EQ(fine.vertices.size(), 17u * 17u);  // a 16 × 16 grid of cells
    // Original vertices keep their indices and positions.
    for (std::size_t i = 0; i < square.vertices.size(); ++i) EXPECT_EQ(fine.vertices[i].position, square.vertices[i].position);
    int boundary = 0;
    for (const auto& [edge, count] : edgeUses(fine, fine.parts[0])) {
        EXPECT_LE(count, 2);
        if (count == 1) ++boundary;
    }
    EXPECT_EQ(boundary, 4 * 16);  // only the square's outline is open
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
            EXPECT_LT(bleedSamples.albedo[i].r, 0.1f);  // both paints have red albedo 0.02 / 0.05
        }
    EXPECT_GT(paint, 0);
}
