#pragma once
// One 1-D screen-space SSS pass (renderer/shaders/sss_blur.frag): reads a colour texture (rgb, a = skin mask) and
// the linear depth, writes the blurred colour along one axis with one kernel stage's taps (renderer/sss/kernel.h),
// with the artifact extensions of `extensions` (docs/extensions.md). The CPU mirror is renderer/sss/cpu_blur.cpp
// (tests compare them).
#include "renderer/gl/gl_resources.h"
#include "renderer/gl/sss_extension_settings.h"
#include "renderer/sss/kernel.h"

#include <array>

namespace skinlab::renderer::gl {

class ShaderLibrary;

struct SssBlurPassInputs {
    GLuint source = 0;      // GL_RGBA32F, rgb = colour, a = skin mask 0…1
    GLuint linearDepth = 0; // GL_R32F, world units, +inf on background
    int width = 0;
    int height = 0;
    float focalLengthPixels = 0.0f;
    float mmPerUnit = 1.0f;
    bool followSurface = true;
    float followSurfaceK = 0.5f;     // 1/mm
    SssExtensionSettings extensions; // sss.cbf, sss.lab_weight, sss.curvature and their textures (default: all off)
};

// Uploads a stage's taps to the `taps` (vec4: xyz = RGB weight, w = offset in mm) and `tapCount` uniforms of a
// blur program (sss_blur.frag, pscbf_blur.frag).
void setTapUniforms(GLuint program, const sss::KernelStage& stage);

class SssBlurPass {
public:
    explicit SssBlurPass(ShaderLibrary& shaders);

    // Draws into `target` (a framebuffer whose attachment 0 receives the result; with `accumulate` its attachment
    // 1 receives accumulate · result added by blending — the caller clears it once per frame).
    void run(const SssBlurPassInputs& inputs, const sss::KernelStage& stage, bool horizontal, GLuint target,
             bool accumulate);

private:
    ShaderLibrary& shaders_;
};

} // namespace skinlab::renderer::gl
