#include "renderer/reference/surface_samples.h"

#include <limits>

namespace skinlab::renderer::reference {

SurfaceSamples gatherSurfaceSamples(const Model& model, float mmPerUnit) {
    const std::size_t count = model.vertices.size();
    SurfaceSamples samples;
    samples.positionMm.resize(count);
    samples.normal.resize(count);
    samples.albedo.assign(count, glm::vec3(0.0f));
    samples.areaMm2.assign(count, 0.0f);
    samples.skin.assign(count, 0);
    constexpr std::uint32_t unassigned = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> materialOf(count, unassigned);
    for (std::size_t i = 0; i < count; ++i) {
        samples.positionMm[i] = model.vertices[i].position * mmPerUnit;
        samples.normal[i] = model.vertices[i].normal;
    }
    for (const auto& part : model.parts) {
        const bool skinMaterial = part.material < model.materials.size() && model.materials[part.material].skin;
        for (std::uint32_t i = part.firstIndex; i + 2 < part.firstIndex + part.indexCount; i += 3) {
            const std::uint32_t* triangle = &model.indices[i];
            const glm::vec3& a = samples.positionMm[triangle[0]];
            const glm::vec3& b = samples.positionMm[triangle[1]];
            const glm::vec3& c = samples.positionMm[triangle[2]];
            const float third = glm::length(glm::cross(b - a, c - a)) / 6.0f; // (area / 3), mm²
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t v = triangle[k];
                if (materialOf[v] == unassigned) materialOf[v] = part.material;
                const bool sampleSkin = model.materials.size() > materialOf[v] && model.materials[materialOf[v]].skin;
                if (skinMaterial == sampleSkin) samples.areaMm2[v] += third;
            }
        }
    }
    for (std::size_t i = 0; i < count; ++i) {
        if (materialOf[i] == unassigned) continue;
        const MeshMaterial& material = model.materials[materialOf[i]];
        samples.albedo[i] = material.albedo * model.vertices[i].color;
        samples.skin[i] = material.skin && model.vertices[i].skin >= 0.5f ? 1 : 0;
    }
    return samples;
}

} // namespace skinlab::renderer::reference
