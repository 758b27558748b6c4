#pragma once
// Triangle meshes as the renderer consumes them, whatever their source (assimp, or the procedural built-in
// scenes). Positions in world units (the scene's mm_per_unit gives their physical size).
#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <string>
#include <vector>

namespace skinlab::renderer {

struct Image;

struct Vertex {
    glm::vec3 position{0.0f};
    glm::vec3 normal{0.0f, 0.0f, 1.0f}; // geometric (smooth) normal, unit length
    glm::vec2 uv{0.0f};
    glm::vec4 tangent{1.0f, 0.0f, 0.0f, 1.0f}; // xyz unit tangent, w = handedness (±1) of the bitangent
    glm::vec3 color{1.0f}; // linear albedo multiplier (procedural albedo: lips, brows); 1 for scanned assets
    float skin = 1.0f;     // skin mask multiplier in [0, 1] (multiplied with the material's flag)
};

// A range of indices drawn with one material.
struct SubMesh {
    std::uint32_t firstIndex = 0;
    std::uint32_t indexCount = 0;
    std::uint32_t material = 0; // index into Model::materials
};

// Material as found in the model; the scene spec may override or extend it by name.
struct MeshMaterial {
    std::string name;
    glm::vec3 albedo{1.0f}; // linear
    bool skin = true;
    float glossiness = 0.6f; // thesis Eq. 4.5: alpha = 8192 * glossiness^5
    float specularIntensity = 1.0f;
};

struct Model {
    std::vector<Vertex> vertices;
    std::vector<std::uint32_t> indices;
    std::vector<SubMesh> parts;
    std::vector<MeshMaterial> materials;
    glm::vec3 boundsMin{0.0f};
    glm::vec3 boundsMax{0.0f};
    // Maps the model brings itself (the procedural skin maps of builtin:head; null: none). A scene spec's
    // textures.albedo / textures.normal replace them.
    std::shared_ptr<const Image> albedoMap;
    std::shared_ptr<const Image> normalMap;

    void computeBounds();
};

} // namespace skinlab::renderer
