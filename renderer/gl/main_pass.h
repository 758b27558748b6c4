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

    // Sets every uniform of main_pass.frag except the per-part material ones and binds its textures (units 0–5
    // and any further ones it needs), for `program` = main_pass.frag linked with any vertex shader that writes
    // the same outputs as main_pass.vert (the object-space reference bakes the same shading at mesh vertices).
    // unbindShading() unbinds the units again.
    static void bindShading(GLuint program, const GpuScene& scene, GLuint shadowMaps, const MainPassSettings& settings);
    static void unbindShading();
    // Per-part material uniforms.
    static void setMaterial(GLuint program, const GpuMaterial& material);

private:
    ShaderLibrary& shaders_;
};

} // namespace skinlab::renderer::gl
