#include "renderer/gl/shadow_map_pass.h"

#include "common/error.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

namespace skinlab::renderer::gl {

ShadowMapPass::ShadowMapPass(ShaderLibrary& shaders) : shaders_(shaders) { allocate(1, 1); }

void ShadowMapPass::allocate(int resolution, int layers) {
    if (resolution == resolution_ && layers == layers_) return;
    GLuint name = 0;
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &name);
    shadowMaps_ = Texture(name);
    glTextureStorage3D(name, 1, GL_DEPTH_COMPONENT32F, resolution, resolution, layers);
    glTextureParameteri(name, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(name, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(name, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(name, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTextureParameteri(name, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTextureParameteri(name, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    framebuffers_.clear();
    for (int layer = 0; layer < layers; ++layer) {
        GLuint framebuffer = 0;
        glCreateFramebuffers(1, &framebuffer);
        glNamedFramebufferTextureLayer(framebuffer, GL_DEPTH_ATTACHMENT, name, 0, layer);
        glNamedFramebufferDrawBuffer(framebuffer, GL_NONE);
        if (glCheckNamedFramebufferStatus(framebuffer, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
            throw RuntimeError("shadow map pass: framebuffer of layer " + std::to_string(layer) + " incomplete");
        framebuffers_.emplace_back(framebuffer);
    }
    resolution_ = resolution;
    layers_ = layers;
    checkGl("allocating shadow maps");
}

void ShadowMapPass::run(GpuScene& scene, const glm::vec3& boundsMin, const glm::vec3& boundsMax, int resolution) {
    const glm::vec3 centre = 0.5f * (boundsMin + boundsMax);
    const float radius = std::max(0.5f * glm::length(boundsMax - boundsMin), 1e-4f);
    int layers = 0;
    for (GpuLight& light : scene.lights) {
        light.shadowLayer = -1;
        if (!light.castsShadow) continue;
        light.shadowLayer = layers++;
        // An up vector not parallel to the light's axis.
        const glm::vec3 up = std::abs(light.direction.y) > 0.99f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
        float texelWorld = 0;
        if (light.type == 0) {
            const glm::vec3 eye = centre - light.direction * (2.0f * radius);
            const glm::mat4 view = glm::lookAt(eye, centre, up);
            light.viewProjection = glm::ortho(-radius, radius, -radius, radius, radius * 0.9f, radius * 3.1f) * view;
            texelWorld = 2.0f * radius / static_cast<float>(resolution);
        } else {
            const glm::mat4 view = glm::lookAt(light.position, light.position + light.direction, up);
            const float distance = glm::length(centre - light.position);
            const float farPlane = distance + radius * 1.05f;
            const float nearPlane = std::max(distance - radius * 1.05f, farPlane * 1e-3f);
            const float halfAngle = std::acos(std::clamp(light.cosOuter, -1.0f, 1.0f));
            light.viewProjection = glm::perspective(2.0f * halfAngle, 1.0f, nearPlane, farPlane) * view;
            texelWorld = 2.0f * light.referenceDistance * std::tan(halfAngle) / static_cast<float>(resolution);
        }
        // Receivers are pushed 1.5 shadow texels along their normal (normal-offset shadows) against acne.
        light.normalOffset = 1.5f * texelWorld;
    }
    allocate(layers > 0 ? resolution : 1, std::max(layers, 1));
    if (layers == 0) return;

    const GLuint program = shaders_.program("shadow_map.vert", "shadow_map.frag");
    glUseProgram(program);
    glViewport(0, 0, resolution, resolution);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    // Slope-scaled bias on the caster side in addition to the receivers' normal offset.
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.5f, 2.0f);
    for (const GpuLight& light : scene.lights) {
        if (light.shadowLayer < 0) continue;
        glBindFramebuffer(GL_FRAMEBUFFER, framebuffers_[static_cast<std::size_t>(light.shadowLayer)].get());
        const float one = 1.0f;
        glClearBufferfv(GL_DEPTH, 0, &one);
        setUniform(program, "lightViewProjection", light.viewProjection);
        scene.drawAll();
    }
    glDisable(GL_POLYGON_OFFSET_FILL);
    glDisable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
    checkGl("shadow map pass");
}

} // namespace skinlab::renderer::gl
