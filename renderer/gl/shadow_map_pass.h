#pragma once
// Shadow map pass (shadow_map.vert/.frag): the scene's depth from each shadow-casting light, one layer of a
// depth texture array per light, sampled with hardware comparison + PCF in main_pass.frag.
// Directional lights use an orthographic projection around the scene's bounding sphere, spot lights a
// perspective one with the spot's cone (2 × outer angle) as field of view.
#include "renderer/gl/gpu_scene.h"
#include "renderer/gl/shader_library.h"

namespace skinlab::renderer::gl {

class ShadowMapPass {
public:
    explicit ShadowMapPass(ShaderLibrary& shaders);

    // Assigns layers and view-projection matrices to the shadow-casting lights of `scene` (bounds: the whole
    // scene, world units) and renders their depth at resolution² texels.
    void run(GpuScene& scene, const glm::vec3& boundsMin, const glm::vec3& boundsMax, int resolution);

    // GL_TEXTURE_2D_ARRAY of GL_DEPTH_COMPONENT32F with compare mode on (at least one 1×1 layer).
    GLuint shadowMaps() const { return shadowMaps_.get(); }

private:
    void allocate(int resolution, int layers);
    ShaderLibrary& shaders_;
    Texture shadowMaps_;
    std::vector<Framebuffer> framebuffers_;
    int resolution_ = 0;
    int layers_ = 0;
};

} // namespace skinlab::renderer::gl
