#pragma once
// Point samples of a model's surface for the object-space reference: one sample per vertex, carrying the vertex's
// position and normal (in millimetres / unit length), its linear albedo, whether it is skin, and the surface area it
// stands for (one third of each incident triangle's area, so the areas sum to the surface area).
#include "renderer/scene/mesh.h"

#include <cstdint>
#include <vector>

namespace skinlab::renderer::reference {

struct SurfaceSamples {
    std::vector<glm::vec3> positionMm; // world position × mm_per_unit
    std::vector<glm::vec3> normal;     // unit, world space (the vertex's smooth geometric normal)
    std::vector<glm::vec3> albedo;     // linear Rec.709: material albedo × vertex colour (textures not applied)
    std::vector<float> areaMm2;        // area represented by the sample, mm²
    std::vector<std::uint8_t> skin;    // 1: skin (scatters and receives), 0: not

    std::size_t size() const { return positionMm.size(); }
};

// A vertex is a skin sample when its mask multiplier Vertex::skin is ≥ 0.5 and the first triangle that uses it
// belongs to a skin material; its albedo is that material's albedo × Vertex::color. The area of a skin sample
// counts only skin triangles (so non-skin area never enters the convolution). Unused vertices get area 0.
SurfaceSamples gatherSurfaceSamples(const Model& model, float mmPerUnit);

} // namespace skinlab::renderer::reference
