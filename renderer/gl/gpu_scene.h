#pragma once
// A scene as the GL passes see it: the model's vertex/index buffers, per-part materials, the texture maps,
// the environment (equirect texture + irradiance SH) and the lights with their shadow matrices. Built from
// GL-free data (Model, Image, Environment) by renderer.cpp.
#include "renderer/gl/gl_resources.h"
#include "renderer/scene/mesh.h"

#include <array>
#include <glm/glm.hpp>
#include <vector>

namespace skinlab::renderer {
struct Image;
struct Environment;
}

namespace skinlab::renderer::gl {

struct GpuMaterial {
    glm::vec3 albedo{1.0f}; // linear
    float skin = 1.0f;      // 0 or 1 (multiplied with vertex skin and the mask map)
    float glossiness = 0.6f;
    float specularIntensity = 1.0f;
};

struct GpuPart {
    std::uint32_t firstIndex = 0;
    std::uint32_t indexCount = 0;
    GpuMaterial material;
};

struct GpuLight {
    int type = 0;                  // 0 directional, 1 spot
    glm::vec3 direction{0, 0, -1}; // travel direction / spot axis (unit)
    glm::vec3 position{0.0f};
    glm::vec3 radiance{1.0f};       // colour * intensity
    float referenceDistance = 1.0f; // spot
    float cosInner = 1.0f;
    float cosOuter = 0.0f;
    bool castsShadow = false;
    int shadowLayer = -1;           // layer of the shadow map array, -1: none (set by ShadowMapPass)
    glm::mat4 viewProjection{1.0f}; // world → light clip space (shadow casting lights)
    float normalOffset = 0.0f;      // world units
};

// A vertex array over a buffer of renderer::Vertex with the attribute layout main_pass.vert reads (locations 0–5:
// position, normal, uv, tangent, colour, skin) and `indexBuffer` as its element buffer.
VertexArray createModelVertexArray(GLuint vertexBuffer, GLuint indexBuffer);

class GpuScene {
public:
    // Uploads the model (positions in world units) and its parts' materials.
    void uploadModel(const Model& model, const std::vector<GpuMaterial>& partMaterials);
    // Optional maps (nullptr: absent). Albedo is linear already (decoded by loadTexture); mipmapped.
    void uploadMaps(const Image* albedo, const Image* normal, const Image* specular, const Image* occlusion,
                    const Image* skinMask);
    // Equirect radiance texture (for the background), the irradiance SH coefficients (A_l L_lm) and, for
    // environment.irradiance = "exact", the irradiance map (renderer/scene/environment.h, irradianceMap; nullptr:
    // the shader evaluates the SH coefficients).
    void uploadEnvironment(const Environment* environment, const std::array<glm::vec3, 9>& irradianceCoefficients,
                           const Environment* irradiance = nullptr);

    void drawAll() const; // all parts, no material uniforms (shadow pass)
    const std::vector<GpuPart>& parts() const { return parts_; }
    void drawPart(const GpuPart& part) const;

    GLuint albedoMap() const { return albedoMap_.get(); }
    GLuint normalMap() const { return normalMap_.get(); }
    GLuint specularMap() const { return specularMap_.get(); }
    GLuint occlusionMap() const { return occlusionMap_.get(); }
    GLuint skinMaskMap() const { return skinMaskMap_.get(); }
    GLuint environmentMap() const { return environmentMap_.get(); }
    GLuint irradianceMap() const { return irradianceMap_.get(); } // 0: none (the SH coefficients light)
    GLuint fallbackMap() const { return fallbackMap_.get(); }     // 1×1 white, bound where a map is absent
    const std::array<glm::vec3, 9>& irradianceCoefficients() const { return irradiance_; }

    std::vector<GpuLight> lights;

private:
    VertexArray vertexArray_;
    Buffer vertexBuffer_;
    Buffer indexBuffer_;
    std::vector<GpuPart> parts_;
    Texture albedoMap_, normalMap_, specularMap_, occlusionMap_, skinMaskMap_, environmentMap_, irradianceMap_,
        fallbackMap_;
    std::array<glm::vec3, 9> irradiance_{};
};

} // namespace skinlab::renderer::gl
