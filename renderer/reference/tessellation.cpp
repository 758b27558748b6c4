#include "renderer/reference/tessellation.h"

#include "common/error.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <unordered_map>

namespace skinlab::renderer::reference {

namespace {
bool isSkinPart(const Model& model, const SubMesh& part) {
    return part.material < model.materials.size() && model.materials[part.material].skin;
}

Vertex midpoint(const Vertex& a, const Vertex& b) {
    Vertex m;
    m.position = 0.5f * (a.position + b.position);
    const glm::vec3 normal = a.normal + b.normal;
    m.normal = glm::length(normal) > 0.0f ? glm::normalize(normal) : a.normal; // opposite normals: keep a's
    m.uv = 0.5f * (a.uv + b.uv);
    const glm::vec3 tangent = glm::vec3(a.tangent) + glm::vec3(b.tangent);
    m.tangent = glm::vec4(glm::length(tangent) > 0.0f ? glm::normalize(tangent) : glm::vec3(a.tangent), a.tangent.w);
    m.color = 0.5f * (a.color + b.color);
    m.skin = 0.5f * (a.skin + b.skin);
    return m;
}

std::uint64_t edgeKey(std::uint32_t a, std::uint32_t b) {
    const std::uint32_t low = std::min(a, b);
    const std::uint32_t high = std::max(a, b);
    return (static_cast<std::uint64_t>(low) << 32) | high;
}

// One refinement round (Carstensen's red-green-blue refinement, restricted to the skin parts):
//  1. mark every skin edge longer than the target;
//  2. closure: a triangle with any marked edge gets its longest edge marked too (repeated until stable), so every
//     split triangle is bisected through its longest edge first, which keeps the angles bounded away from 0 (a
//     newest-vertex bisection of a non-longest edge would make ever thinner slivers);
//  3. split each skin triangle by its marked edges: none → kept; the longest only → 2 (green: longest-edge
//     bisection); the longest and one more → 3 (blue: bisect the longest, then the sub-triangle holding the
//     other marked edge from the longest edge's midpoint, so that is the diagonal); all three → 4 (red: at the
//     midpoints).
// A marked edge gets one midpoint through the edge map, used by both triangles sharing it: the mesh stays
// conforming. Returns the number of marked edges (0: nothing was split).
struct EdgeTable {
    std::unordered_map<std::uint64_t, std::uint32_t> midpoint; // marked edge → its new vertex (assigned later)
    std::unordered_map<std::uint64_t, float> lengthSquared;
};

float lengthSquared(const Model& model, std::uint32_t a, std::uint32_t b) {
    const glm::vec3 d = model.vertices[a].position - model.vertices[b].position;
    return glm::dot(d, d);
}

// Rotation r (0, 1, 2) such that edge (t[r], t[r+1]) is the triangle's longest; ties broken by the edge key so
// the choice does not depend on the vertex order.
int longestEdgeOf(const Model& model, const std::uint32_t* t) {
    int best = 0;
    float bestLength = -1.0f;
    std::uint64_t bestKey = 0;
    for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = t[k], b = t[(k + 1) % 3];
        const float length = lengthSquared(model, a, b);
        const std::uint64_t key = edgeKey(a, b);
        if (length > bestLength || (length == bestLength && key > bestKey)) {
            best = k;
            bestLength = length;
            bestKey = key;
        }
    }
    return best;
}

template <class Visit>
void forEachSkinTriangle(const Model& model, Visit&& visit) {
    for (const auto& part : model.parts) {
        if (!isSkinPart(model, part)) continue;
        for (std::uint32_t i = part.firstIndex; i + 2 < part.firstIndex + part.indexCount; i += 3)
            visit(&model.indices[i]);
    }
}

// Marks the edges to split this round (steps 1 and 2); the values of the map are assigned by splitMarked.
std::unordered_map<std::uint64_t, std::uint32_t> markEdges(const Model& model, float targetUnits) {
    std::unordered_map<std::uint64_t, std::uint32_t> marked;
    const float targetSquared = targetUnits * targetUnits;
    forEachSkinTriangle(model, [&](const std::uint32_t* t) {
        for (int k = 0; k < 3; ++k)
            if (lengthSquared(model, t[k], t[(k + 1) % 3]) > targetSquared)
                marked.emplace(edgeKey(t[k], t[(k + 1) % 3]), 0u);
    });
    // Closure: marks only grow, so this ends (at the latest when every edge is marked).
    for (bool changed = !marked.empty(); changed;) {
        changed = false;
        forEachSkinTriangle(model, [&](const std::uint32_t* t) {
            const int r = longestEdgeOf(model, t);
            const std::uint64_t longest = edgeKey(t[r], t[(r + 1) % 3]);
            if (marked.count(longest)) return;
            for (int k = 0; k < 3; ++k)
                if (marked.count(edgeKey(t[k], t[(k + 1) % 3]))) {
                    marked.emplace(longest, 0u);
                    changed = true;
                    return;
                }
        });
    }
    return marked;
}

// Step 3. New vertices are appended in the order the marked edges are first met (deterministic).
void splitMarked(Model& model, std::unordered_map<std::uint64_t, std::uint32_t>& marked) {
    constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();
    for (auto& entry : marked) entry.second = none;
    const auto midpointIndex = [&](std::uint32_t a, std::uint32_t b) -> std::uint32_t {
        const auto found = marked.find(edgeKey(a, b));
        if (found == marked.end()) return none;
        if (found->second == none) {
            found->second = static_cast<std::uint32_t>(model.vertices.size());
            const Vertex m = midpoint(model.vertices[a], model.vertices[b]);
            model.vertices.push_back(m);
        }
        return found->second;
    };
    std::vector<std::uint32_t> indices;
    indices.reserve(model.indices.size() * 2);
    for (auto& part : model.parts) {
        const std::uint32_t first = static_cast<std::uint32_t>(indices.size());
        const std::uint32_t end = part.firstIndex + part.indexCount;
        if (!isSkinPart(model, part)) {
            indices.insert(indices.end(), model.indices.begin() + part.firstIndex, model.indices.begin() + end);
        } else {
            for (std::uint32_t i = part.firstIndex; i + 2 < end; i += 3) {
                // Rotate (keeps the winding) so that a–b is the longest edge, c the opposite vertex.
                const int r = longestEdgeOf(model, &model.indices[i]);
                const std::uint32_t a = model.indices[i + r], b = model.indices[i + (r + 1) % 3],
                                    c = model.indices[i + (r + 2) % 3];
                const std::uint32_t ab = midpointIndex(a, b);
                if (ab == none) { // no marked edge (the closure marks the longest edge of every split triangle):
                    // kept exactly as it was, vertex order included
                    indices.insert(indices.end(), model.indices.begin() + i, model.indices.begin() + i + 3);
                    continue;
                }
                const std::uint32_t bc = midpointIndex(b, c), ca = midpointIndex(c, a);
                if (bc != none && ca != none)
                    indices.insert(indices.end(), {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca});
                else if (bc != none) indices.insert(indices.end(), {a, ab, c, ab, b, bc, ab, bc, c});
                else if (ca != none) indices.insert(indices.end(), {a, ab, ca, ab, c, ca, ab, b, c});
                else indices.insert(indices.end(), {a, ab, c, ab, b, c});
            }
        }
        part.firstIndex = first;
        part.indexCount = static_cast<std::uint32_t>(indices.size()) - first;
    }
    model.indices = std::move(indices);
}
// Calls visit(a, b, c) with the corner positions (world units) of every triangle of the skin parts.
template <class Visit>
void forEachSkinTrianglePositions(const Model& model, Visit&& visit) {
    forEachSkinTriangle(model, [&](const std::uint32_t* corner) {
        visit(model.vertices[corner[0]].position, model.vertices[corner[1]].position,
              model.vertices[corner[2]].position);
    });
}
} // namespace

float longestSkinEdgeMm(const Model& model, float mmPerUnit) {
    float longest = 0.0f;
    forEachSkinTrianglePositions(model, [&](const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
        longest = std::max({longest, glm::length(a - b), glm::length(b - c), glm::length(c - a)});
    });
    return longest * mmPerUnit;
}

Model tessellateSkin(const Model& model, float targetEdgeMm, float mmPerUnit, TessellationStatistics* statistics,
                     std::size_t maxVertices) {
    if (!(targetEdgeMm > 0.0f)) throwInput("reference", "edge_mm", std::to_string(targetEdgeMm) + " must be positive");
    if (!(mmPerUnit > 0.0f)) throwInput("reference", "mm_per_unit", std::to_string(mmPerUnit) + " must be positive");
    // Refuse at once what cannot fit: every final skin triangle has edges ≤ the target, so area ≤ (√3/4)·edge²,
    // and a triangle mesh has at least half as many vertices as triangles (Euler, up to its boundary and genus).
    double skinAreaMm2 = 0.0;
    forEachSkinTrianglePositions(model, [&](const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
        skinAreaMm2 += 0.5 * double(glm::length(glm::cross(b - a, c - a))) * double(mmPerUnit) * double(mmPerUnit);
    });
    const double fewestVertices =
        0.5 * skinAreaMm2 / (0.25 * std::sqrt(3.0) * double(targetEdgeMm) * double(targetEdgeMm));
    if (fewestVertices > double(maxVertices))
        throwInput("reference", "edge_mm",
                   std::to_string(targetEdgeMm) + " mm needs more than " + std::to_string(maxVertices) +
                       " vertices (at least " + std::to_string(static_cast<long long>(fewestVertices)) + " for " +
                       std::to_string(static_cast<long long>(skinAreaMm2)) + " mm² of skin); use a larger edge length");
    Model result = model;
    int rounds = 0;
    const float targetUnits = targetEdgeMm / mmPerUnit;
    float longest = longestSkinEdgeMm(result, mmPerUnit);
    while (longest > targetEdgeMm) {
        auto marked = markEdges(result, targetUnits);
        if (marked.empty()) break; // every edge within the target in world units (rounding at the boundary)
        const std::size_t next = result.vertices.size() + marked.size();
        if (next > maxVertices)
            throwInput("reference", "edge_mm",
                       std::to_string(targetEdgeMm) + " mm needs more than " + std::to_string(maxVertices) +
                           " vertices (longest skin edge is still " + std::to_string(longest) + " mm after " +
                           std::to_string(rounds) + " rounds); use a larger edge length");
        splitMarked(result, marked);
        ++rounds;
        longest = longestSkinEdgeMm(result, mmPerUnit);
    }
    if (statistics) {
        statistics->rounds = rounds;
        statistics->longestSkinEdgeMm = longest;
        statistics->skinTriangles = 0;
        for (const auto& part : result.parts)
            if (isSkinPart(result, part)) statistics->skinTriangles += part.indexCount / 3;
    }
    result.computeBounds();
    return result;
}

} // namespace skinlab::renderer::reference
