#pragma once
// Background pass (fullscreen.vert + background.frag): fills the pixels no geometry covered with the
// environment's radiance (or a constant colour), in the diffuse buffer, mask 0, depth left at +inf.
#include "renderer/gl/frame_targets.h"
#include "renderer/gl/shader_library.h"
#include "renderer/scene/scene_spec.h"

namespace skinlab::renderer::gl {

struct BackgroundSettings {
    CameraPose camera;
    GLuint environmentMap = 0; // 0: use `color`
    glm::vec3 color{0.0f};     // radiance
    float environmentIntensity = 1.0f;
    float exposure = 1.0f;
    glm::mat3 environmentFromWorld{1.0f};
};

class BackgroundPass {
public:
    explicit BackgroundPass(ShaderLibrary& shaders) : shaders_(shaders) {}
    void run(FrameTargets& targets, const BackgroundSettings& settings);

private:
    ShaderLibrary& shaders_;
};

} // namespace skinlab::renderer::gl
