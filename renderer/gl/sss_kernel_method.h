#pragma once
// Runs an SSS method's kernel (renderer/sss/kernel.h) on the GPU with SssBlurPass: for each stage a horizontal and
// a vertical pass. One stage (separable, artistic): diffuse → scratch A → output. Several stages (gaussian-sum,
// Jimenez & Gutierrez 2010): stage i blurs stage i−1's result (scratch A ↔ B) and its vertical pass also adds
// accumulate_i · result into the output by blending (12 passes for six Gaussians).
#include "renderer/gl/gl_resources.h"
#include "renderer/gl/sss_blur_pass.h"
#include "renderer/sss/kernel.h"

namespace skinlab::renderer::gl {

class SssKernelMethod {
public:
    explicit SssKernelMethod(ShaderLibrary& shaders);

    // `inputs.source` = the diffuse buffer (rgb, a = mask); `output` GL_RGBA32F of the same size, not an input.
    void run(const SssBlurPassInputs& inputs, const sss::Kernel& kernel, GLuint output);

private:
    void ensureScratch(int width, int height);
    SssBlurPass pass_;
    Texture scratchA_;
    Texture scratchB_;
    int width_ = 0;
    int height_ = 0;
};

} // namespace skinlab::renderer::gl
