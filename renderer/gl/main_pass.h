#pragma once
// Main pass (main_pass.vert/.frag): lights (with shadows) + IBL irradiance × AO → diffuse × albedo,
// thesis Eq. 4.5 specular in its own buffer, and the AOVs (albedo, linear depth, normals, skin mask).
#include "renderer/gl/frame_targets.h"
#include "renderer/gl/gpu_scene.h"
#include "renderer/gl/shader_library.h"
#include "renderer/scene/scene_spec.h"

namespace skinlab::renderer::gl {

struct MainPassSettings {
    CameraPose camera;
    float exposure = 1.0f;             // 2^exposure_ev
    float normalStrength = 1.0f;
    int pcfRadius = 1;
    glm::mat3 environmentFromWorld{1.0f};
};

class MainPass {
public:
    explicit MainPass(ShaderLibrary& shaders) : shaders_(shaders) {}
    // Clears the frame targets and draws every part of the scene into them.
    void run(FrameTargets& targets, const GpuScene& scene, GLuint shadowMaps, const MainPassSettings& settings);

private:
    ShaderLibrary& shaders_;
};

} // namespace skinlab::renderer::gl
