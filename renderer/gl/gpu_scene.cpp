#include "renderer/gl/gpu_scene.h"

#include "renderer/scene/environment.h"
#include "renderer/scene/texture.h"

#include <cmath>
#include <cstddef>

namespace skinlab::renderer::gl {

VertexArray createModelVertexArray(GLuint vertexBuffer, GLuint indexBuffer) {
    GLuint vao = 0;
    glCreateVertexArrays(1, &vao);
    glVertexArrayVertexBuffer(vao, 0, vertexBuffer, 0, sizeof(Vertex));
    glVertexArrayElementBuffer(vao, indexBuffer);
    struct Attribute {
        GLuint index;
        GLint size;
        std::size_t offset;
    };
    const Attribute attributes[] = {{0, 3, offsetof(Vertex, position)}, {1, 3, offsetof(Vertex, normal)},
                                    {2, 2, offsetof(Vertex, uv)},       {3, 4, offsetof(Vertex, tangent)},
                                    {4, 3, offsetof(Vertex, color)},    {5, 1, offsetof(Vertex, skin)}};
    for (const Attribute& a : attributes) {
        glEnableVertexArrayAttrib(vao, a.index);
        glVertexArrayAttribFormat(vao, a.index, a.size, GL_FLOAT, GL_FALSE, static_cast<GLuint>(a.offset));
        glVertexArrayAttribBinding(vao, a.index, 0);
    }
    return VertexArray(vao);
}

void GpuScene::uploadModel(const Model& model, const std::vector<GpuMaterial>& partMaterials) {
    GLuint name = 0;
    glCreateBuffers(1, &name);
    vertexBuffer_ = Buffer(name);
    glNamedBufferStorage(name, static_cast<GLsizeiptr>(model.vertices.size() * sizeof(Vertex)), model.vertices.data(),
                         0);
    glCreateBuffers(1, &name);
    indexBuffer_ = Buffer(name);
    glNamedBufferStorage(name, static_cast<GLsizeiptr>(model.indices.size() * sizeof(std::uint32_t)),
                         model.indices.data(), 0);
    vertexArray_ = createModelVertexArray(vertexBuffer_.get(), indexBuffer_.get());
    parts_.clear();
    for (std::size_t i = 0; i < model.parts.size(); ++i)
        parts_.push_back({model.parts[i].firstIndex, model.parts[i].indexCount, partMaterials.at(i)});
    checkGl("uploading the model");
}

namespace {

Texture uploadImage(const Image* image, GLenum internalFormat, bool mipmapped) {
    if (!image) return {};
    int levels = 1;
    if (mipmapped) {
        int size = std::max(image->width, image->height);
        while (size > 1) {
            size /= 2;
            ++levels;
        }
    }
    Texture texture = createTexture2D(internalFormat, image->width, image->height, levels);
    // Rows top first, as stored: GL's t = 0 is then the image top, matching the models' v = 0 (texture.h).
    glTextureSubImage2D(texture.get(), 0, 0, 0, image->width, image->height, GL_RGBA, GL_FLOAT, image->pixels.data());
    glTextureParameteri(texture.get(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(texture.get(), GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTextureParameteri(texture.get(), GL_TEXTURE_WRAP_T, GL_REPEAT);
    if (levels > 1) {
        glGenerateTextureMipmap(texture.get());
        glTextureParameterf(texture.get(), GL_TEXTURE_MAX_ANISOTROPY, 8.0f);
    } else {
        glTextureParameteri(texture.get(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    }
    checkGl("uploading a texture map");
    return texture;
}

} // namespace

void GpuScene::uploadMaps(const Image* albedo, const Image* normal, const Image* specular, const Image* occlusion,
                          const Image* skinMask) {
    albedoMap_ = uploadImage(albedo, GL_RGBA16F, true);
    normalMap_ = uploadImage(normal, GL_RGBA16F, true);
    specularMap_ = uploadImage(specular, GL_RGBA16F, true);
    occlusionMap_ = uploadImage(occlusion, GL_RGBA16F, true);
    skinMaskMap_ = uploadImage(skinMask, GL_RGBA16F, true);
    if (!fallbackMap_.get()) {
        fallbackMap_ = createTexture2D(GL_RGBA16F, 1, 1);
        const float white[4] = {1, 1, 1, 1};
        glTextureSubImage2D(fallbackMap_.get(), 0, 0, 0, 1, 1, GL_RGBA, GL_FLOAT, white);
    }
}

namespace {
// An equirectangular map as a linear-filtered RGB32F texture whose u wraps around the horizon.
Texture uploadEquirect(const Environment& map) {
    Texture texture = createTexture2D(GL_RGB32F, map.width, map.height);
    glTextureSubImage2D(texture.get(), 0, 0, 0, map.width, map.height, GL_RGB, GL_FLOAT, map.pixels.data());
    glTextureParameteri(texture.get(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(texture.get(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(texture.get(), GL_TEXTURE_WRAP_S, GL_REPEAT);
    return texture;
}
} // namespace

void GpuScene::uploadEnvironment(const Environment* environment, const std::array<glm::vec3, 9>& irradianceCoefficients,
                                 const Environment* irradiance) {
    irradiance_ = irradianceCoefficients;
    irradianceMap_.reset();
    if (irradiance) {
        irradianceMap_ = uploadEquirect(*irradiance);
        glTextureParameteri(irradianceMap_.get(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        checkGl("uploading the irradiance map");
    }
    environmentMap_.reset();
    if (!environment) return;
    environmentMap_ = uploadEquirect(*environment);
    checkGl("uploading the environment");
}

void GpuScene::drawAll() const {
    glBindVertexArray(vertexArray_.get());
    for (const GpuPart& part : parts_)
        glDrawElements(
            GL_TRIANGLES, static_cast<GLsizei>(part.indexCount), GL_UNSIGNED_INT,
            reinterpret_cast<const void*>(static_cast<std::uintptr_t>(part.firstIndex) * sizeof(std::uint32_t)));
    glBindVertexArray(0);
}

void GpuScene::drawPart(const GpuPart& part) const {
    glBindVertexArray(vertexArray_.get());
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(part.indexCount), GL_UNSIGNED_INT,
                   reinterpret_cast<const void*>(static_cast<std::uintptr_t>(part.firstIndex) * sizeof(std::uint32_t)));
    glBindVertexArray(0);
}

} // namespace skinlab::renderer::gl
