#include "renderer/gl/sss_stage.h"

#include "common/error.h"
#include "renderer/gl/gl_resources.h"
#include "renderer/gl/pscbf_method.h" // pscbf (Mikkelsen 2010)
#include "renderer/gl/shader_library.h"
#include "renderer/gl/sss_kernel_method.h"
#include "renderer/sss/kernel.h"
#include "renderer/sss/sss_params.h"

namespace skinlab::renderer::gl {

struct SssStage::Impl {
    explicit Impl(ShaderLibrary& library) : shaders(library), kernelMethod(library) {}
    ShaderLibrary& shaders;
    // gaussian-sum, separable, artistic: the method's kernel run as 1-D passes.
    SssKernelMethod kernelMethod;
    // The kernel of the last settings (computing a Burley or file: kernel takes milliseconds; renders repeat).
    std::string kernelKey;
    sss::Kernel kernel;
    sss::SssParams params;
    // pscbf (Mikkelsen 2010; renderer/gl/pscbf_method.h), created on first use.
    std::unique_ptr<PscbfMethod> pscbfMethod;

    const sss::Kernel& kernelFor(const SssStageSettings& settings) {
        const std::string key = settings.sss.toJson().dump();
        if (key != kernelKey) {
            params = settings.sss;
            kernel = sss::makeKernel(params);
            kernelKey = key;
        }
        return kernel;
    }
};

SssStage::SssStage(ShaderLibrary& shaders) : impl_(std::make_unique<Impl>(shaders)) {}
SssStage::~SssStage() = default;

void SssStage::run(const SssStageInputs& inputs, const SssStageSettings& settings, GLuint output) {
    if (output == inputs.diffuse) throw RuntimeError("SSS stage: output texture must differ from the diffuse input");
    const sss::Kernel& kernel = impl_->kernelFor(settings);
    const sss::SssParams& params = impl_->params;
    switch (params.method) {
    case sss::SssMethod::Reference:
        // Computed on the surface, not on the screen: renderer.cpp runs ReferenceMethod instead of this stage.
        throw RuntimeError("SSS stage: method reference is run by ReferenceMethod, not by the screen-space stage");
    case sss::SssMethod::Pscbf: {
        // Mikkelsen 2010: its own two passes (renderer/gl/pscbf_method.h).
        if (!impl_->pscbfMethod) impl_->pscbfMethod = std::make_unique<PscbfMethod>(impl_->shaders);
        impl_->pscbfMethod->run(inputs, params, kernel, output);
        return;
    }
    case sss::SssMethod::GaussianSum:
    case sss::SssMethod::Separable:
    case sss::SssMethod::Artistic: {
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
    case sss::SssMethod::None:
    case sss::SssMethod::Pathtraced: // Cycles replaces the image afterwards (renderer.cpp); copy through
    case sss::SssMethod::Eevee:      // EEVEE, likewise
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

float SssStage::supportRadiusMm(const SssStageSettings& settings) const {
    // 0 for none; pscbf's kernel declares its filter disc r_max × width_mm / 3 (renderer/sss/kernel.h).
    return static_cast<float>(impl_->kernelFor(settings).supportRadiusMm());
}

} // namespace skinlab::renderer::gl
