#include "renderer/gl/sss_stage.h"

#include "common/error.h"
#include "renderer/gl/gl_resources.h"
#include "renderer/gl/pscbf_method.h" // pscbf (Mikkelsen 2010)
#include "renderer/gl/shader_library.h"
#include "renderer/gl/sss_kernel_method.h"
#include "renderer/sss/method.h"
#include "renderer/sss/sss_params.h"

namespace skinlab::renderer::gl {

struct SssStage::Impl {
    explicit Impl(ShaderLibrary& library) : shaders(library), kernelMethod(library) {}
    ShaderLibrary& shaders;
    // Execution::TapPasses: the method's kernel run as 1-D passes.
    SssKernelMethod kernelMethod;
    // Execution::Pscbf (Mikkelsen 2010; renderer/gl/pscbf_method.h), created on first use.
    std::unique_ptr<PscbfMethod> pscbfMethod;
};

SssStage::SssStage(ShaderLibrary& shaders) : impl_(std::make_unique<Impl>(shaders)) {}
SssStage::~SssStage() = default;

void SssStage::run(const SssStageInputs& inputs, const SssStageSettings& settings, GLuint output) {
    if (output == inputs.diffuse) throw RuntimeError("SSS stage: output texture must differ from the diffuse input");
    // The kernel of these parameters, built once per parameter set (renderer/sss/method.h).
    const auto prepared = sss::prepareMethod(settings.sss);
    const sss::Kernel& kernel = prepared->kernel;
    const sss::SssParams& params = prepared->params;
    switch (prepared->info->execution) {
    case sss::Execution::ObjectSpace:
        // Computed on the surface, not on the screen: renderer.cpp runs ReferenceMethod instead of this stage.
        throw RuntimeError("SSS stage: method " + std::string(prepared->info->name) +
                           " is run on the surface (ReferenceMethod), not by the screen-space stage");
    case sss::Execution::Pscbf: {
        // Mikkelsen 2010: its own two passes (renderer/gl/pscbf_method.h).
        if (!impl_->pscbfMethod) impl_->pscbfMethod = std::make_unique<PscbfMethod>(impl_->shaders);
        impl_->pscbfMethod->run(inputs, params, kernel, output);
        return;
    }
    case sss::Execution::TapPasses: {
        SssBlurPassInputs passInputs;
        passInputs.source = inputs.diffuse;
        passInputs.linearDepth = inputs.linearDepth;
        passInputs.width = inputs.width;
        passInputs.height = inputs.height;
        passInputs.focalLengthPixels = inputs.focalLengthPixels;
        passInputs.mmPerUnit = inputs.mmPerUnit;
        passInputs.followSurface = params.followSurface;
        passInputs.followSurfaceK = static_cast<float>(params.followSurfaceK);
        passInputs.extensions = SssExtensionSettings::fromParams(params, inputs.albedo, inputs.aux, inputs.curvature);
        impl_->kernelMethod.run(passInputs, kernel, output);
        return;
    }
    case sss::Execution::CopyThrough:
    case sss::Execution::Cycles: // Cycles replaces the image afterwards (renderer.cpp); copy through
    case sss::Execution::Eevee:  // EEVEE, likewise
        break;
    }
    // A framebuffer per run: texture names are recycled when the frame is resized, so caching one by name
    // could keep drawing into a deleted texture.
    const Framebuffer outputFramebuffer = createFramebuffer("SSS stage output", &output, 1);
    // "none": copy the diffuse buffer through (a draw, not glCopyImageSubData, so the stage's cost is measured
    // the same way as the methods that will replace it).
    const GLuint program = impl_->shaders.program("fullscreen.vert", "copy.frag");
    glUseProgram(program);
    glBindFramebuffer(GL_FRAMEBUFFER, outputFramebuffer.get());
    glViewport(0, 0, inputs.width, inputs.height);
    glBindTextureUnit(0, inputs.diffuse);
    impl_->shaders.drawFullscreenTriangle();
    glBindTextureUnit(0, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
    checkGl("SSS stage (none)");
}

} // namespace skinlab::renderer::gl
