#include "renderer/scene/tangent_space.h"

#include <algorithm>
#include <cmath>

namespace skinlab::renderer {
namespace {

// Any unit vector perpendicular to the unit vector n (Frisvad-style branch on the smallest component).
glm::vec3 anyPerpendicular(const glm::vec3& n) {
    const glm::vec3 axis = std::abs(n.x) < 0.9f ? glm::vec3(1.0f, 0.0f, 0.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
    return glm::normalize(glm::cross(axis, n));
}

float cornerAngle(const glm::vec3& corner, const glm::vec3& a, const glm::vec3& b) {
    const glm::vec3 ea = a - corner;
    const glm::vec3 eb = b - corner;
    const float la = glm::length(ea);
    const float lb = glm::length(eb);
    if (la <= 0.0f || lb <= 0.0f) return 0.0f;
    return std::acos(std::clamp(glm::dot(ea, eb) / (la * lb), -1.0f, 1.0f));
}

} // namespace

void computeTangents(Model& model) {
    std::vector<glm::vec3> uDirections(model.vertices.size(), glm::vec3(0.0f));
    std::vector<glm::vec3> vDirections(model.vertices.size(), glm::vec3(0.0f));
    for (std::size_t t = 0; t + 2 < model.indices.size(); t += 3) {
        const std::uint32_t corner[3] = {model.indices[t], model.indices[t + 1], model.indices[t + 2]};
        const Vertex& a = model.vertices[corner[0]];
        const Vertex& b = model.vertices[corner[1]];
        const Vertex& c = model.vertices[corner[2]];
        const glm::vec3 edge1 = b.position - a.position;
        const glm::vec3 edge2 = c.position - a.position;
        const glm::vec2 duv1 = b.uv - a.uv;
        const glm::vec2 duv2 = c.uv - a.uv;
        const float determinant = duv1.x * duv2.y - duv2.x * duv1.y;
        // Degenerate UV mapping (all corners at one UV, or collinear): no gradient to take.
        if (std::abs(determinant) < 1e-20f) continue;
        glm::vec3 dPdu = (edge1 * duv2.y - edge2 * duv1.y) / determinant;
        glm::vec3 dPdv = (edge2 * duv1.x - edge1 * duv2.x) / determinant;
        const float lengthU = glm::length(dPdu);
        const float lengthV = glm::length(dPdv);
        if (!(lengthU > 0.0f) || !(lengthV > 0.0f) || !std::isfinite(lengthU) || !std::isfinite(lengthV)) continue;
        dPdu /= lengthU;
        dPdv /= lengthV;
        const float angles[3] = {cornerAngle(a.position, b.position, c.position),
                                 cornerAngle(b.position, c.position, a.position),
                                 cornerAngle(c.position, a.position, b.position)};
        for (int k = 0; k < 3; ++k) {
            uDirections[corner[k]] += angles[k] * dPdu;
            vDirections[corner[k]] += angles[k] * dPdv;
        }
    }
    for (std::size_t i = 0; i < model.vertices.size(); ++i) {
        Vertex& vertex = model.vertices[i];
        const glm::vec3 n = vertex.normal;
        glm::vec3 tangent = uDirections[i] - n * glm::dot(n, uDirections[i]);
        const float length = glm::length(tangent);
        if (!(length > 1e-6f * std::max(glm::length(uDirections[i]), 1e-30f)) || !std::isfinite(length)) {
            vertex.tangent = glm::vec4(anyPerpendicular(n), 1.0f);
            continue;
        }
        tangent /= length;
        // Bitangent convention: w * cross(N, T) points up the image, i.e. along -∂P/∂v.
        const float handedness = glm::dot(glm::cross(n, tangent), -vDirections[i]) < 0.0f ? -1.0f : 1.0f;
        vertex.tangent = glm::vec4(tangent, handedness);
    }
}

} // namespace skinlab::renderer
