#include "renderer/reference/tessellation.h"

#include "common/error.h"

#include <algorithm>
#include <cstdint>
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
    m.normal = glm::length(normal) > 0.0f ? glm::normalize(normal) : a.normal;  // opposite normals: keep a's
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

// Number of distinct edges of the skin triangles (each becomes one new vertex in a round).
std::size_t countSkinEdges(const Model& model) {
    std::unordered_map<std::uint64_t, bool> edges;
    for (const auto& part : model.parts) {
        if (!isSkinPart(model, part)) continue;
        for (std::uint32_t i = part.firstIndex; i + 2 < part.firstIndex + part.indexCount; i += 3) {
            const std::uint32_t* t = &model.indices[i];
            edges.emplace(edgeKey(t[0], t[1]), true);
            edges.emplace(edgeKey(t[1], t[2]), true);
            edges.emplace(edgeKey(t[2], t[0]), true);
        }
    }
    return edges.size();
}

void splitSkinOnce(Model& model) {
    std::unordered_map<std::uint64_t, std::uint32_t> midpoints;
    const auto midpointIndex = [&](std::uint32_t a, std::uint32_t b) {
        const auto [it, inserted] = midpoints.try_emplace(edgeKey(a, b), 0u);
        if (inserted) {
            it->second = static_cast<std::uint32_t>(model.vertices.size());
            const Vertex m = midpoint(model.vertices[a], model.vertices[b]);
            model.vertices.push_back(m);
        }
        return it->second;
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
                const std::uint32_t a = model.indices[i], b = model.indices[i + 1], c = model.indices[i + 2];
                const std::uint32_t ab = midpointIndex(a, b), bc = midpointIndex(b, c), ca = midpointIndex(c, a);
                // Same winding as the parent triangle.
                indices.insert(indices.end(), {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca});
            }
        }
        part.firstIndex = first;
        part.indexCount = static_cast<std::uint32_t>(indices.size()) - first;
    }
    model.indices = std::move(indices);
}
} // namespace

float longestSkinEdgeMm(const Model& model, float mmPerUnit) {
    float longest = 0.0f;
    for (const auto& part : model.parts) {
        if (!isSkinPart(model, part)) continue;
        for (std::uint32_t i = part.firstIndex; i + 2 < part.firstIndex + part.indexCount; i += 3) {
            const glm::vec3& a = model.vertices[model.indices[i]].position;
            const glm::vec3& b = model.vertices[model.indices[i + 1]].position;
            const glm::vec3& c = model.vertices[model.indices[i + 2]].position;
            longest = std::max({longest, glm::length(a - b), glm::length(b - c), glm::length(c - a)});
        }
    }
    return longest * mmPerUnit;
}

Model tessellateSkin(const Model& model, float targetEdgeMm, float mmPerUnit, TessellationStatistics* statistics,
                     std::size_t maxVertices) {
    if (!(targetEdgeMm > 0.0f)) throwInput("reference", "edge_mm", std::to_string(targetEdgeMm) + " must be positive");
    if (!(mmPerUnit > 0.0f)) throwInput("reference", "mm_per_unit", std::to_string(mmPerUnit) + " must be positive");
    Model result = model;
    int rounds = 0;
    float longest = longestSkinEdgeMm(result, mmPerUnit);
    while (longest > targetEdgeMm) {
        const std::size_t next = result.vertices.size() + countSkinEdges(result);
        if (next > maxVertices)
            throwInput("reference", "edge_mm",
                       std::to_string(targetEdgeMm) + " mm needs more than " + std::to_string(maxVertices) +
                           " vertices (longest skin edge is still " + std::to_string(longest) +
                           " mm after " + std::to_string(rounds) + " rounds); use a larger edge length");
        splitSkinOnce(result);
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
