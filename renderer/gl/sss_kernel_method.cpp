#include "renderer/gl/sss_kernel_method.h"

#include "common/error.h"

namespace skinlab::renderer::gl {

SssKernelMethod::SssKernelMethod(ShaderLibrary& shaders) : pass_(shaders) {}

void SssKernelMethod::ensureScratch(int width, int height) {
    if (width == width_ && height == height_ && scratchA_.get() != 0) return;
    scratchA_ = createTexture2D(GL_RGBA32F, width, height);
    scratchB_ = createTexture2D(GL_RGBA32F, width, height);
    width_ = width;
    height_ = height;
}

void SssKernelMethod::run(const SssBlurPassInputs& inputs, const sss::Kernel& kernel, GLuint output) {
    if (kernel.stages.empty()) throw RuntimeError("SSS kernel method: empty kernel");
    ensureScratch(inputs.width, inputs.height);
    // Framebuffers per run (cheap): the pipeline may recreate `output` between frames.
    const GLuint a = scratchA_.get();
    const GLuint b = scratchB_.get();
    const Framebuffer intoA = createFramebuffer("SSS scratch A", &a, 1);
    const Framebuffer intoOutput = createFramebuffer("SSS output", &output, 1);
    SssBlurPassInputs pass = inputs;
    if (kernel.stages.size() == 1) {
        pass_.run(pass, kernel.stages[0], true, intoA.get(), false);
        pass.source = a;
        pass_.run(pass, kernel.stages[0], false, intoOutput.get(), false);
        return;
    }
    const GLuint vertical[2] = {b, output};
    const Framebuffer intoBAndOutput = createFramebuffer("SSS scratch B + accumulation", vertical, 2);
    const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    glClearTexImage(output, 0, GL_RGBA, GL_FLOAT, zero);
    GLuint current = inputs.source;
    for (const auto& stage : kernel.stages) {
        pass.source = current;
        pass_.run(pass, stage, true, intoA.get(), false);
        pass.source = a;
        pass_.run(pass, stage, false, intoBAndOutput.get(), true);
        current = b;
    }
    checkGl("SSS kernel method");
}

} // namespace skinlab::renderer::gl
