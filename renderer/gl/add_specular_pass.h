#pragma once
// Add specular pass (fullscreen.vert + add_specular.frag): beauty = scattered diffuse + specular.
#include "renderer/gl/frame_targets.h"
#include "renderer/gl/shader_library.h"

namespace skinlab::renderer::gl {

class AddSpecularPass {
public:
    explicit AddSpecularPass(ShaderLibrary& shaders) : shaders_(shaders) {}
    void run(FrameTargets& targets);

private:
    ShaderLibrary& shaders_;
};

} // namespace skinlab::renderer::gl
