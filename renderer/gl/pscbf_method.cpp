#include "renderer/gl/pscbf_method.h"

#include "common/error.h"
#include "renderer/gl/shader_library.h"
#include "renderer/gl/sss_blur_pass.h"
#include "renderer/gl/sss_extension_settings.h"
#include "renderer/sss/methods/pscbf.h"
#include "renderer/sss/pscbf_kernel.h"
#include "renderer/sss/skin_model.h"

#include <cmath>
#include <vector>

namespace skinlab::renderer::gl {

namespace {
// Texture units of pscbf_blur.frag (its layout(binding) values); the extensions take the three after them.
constexpr GLuint kSourceUnit = 0;
constexpr GLuint kDepthUnit = 1;
constexpr GLuint kNormalUnit = 2;
constexpr GLuint kUnblurredUnit = 3;
constexpr GLuint kFirstExtensionUnit = 4;
constexpr int kMaxTaps = 101; // PSCBF_MAX_TAPS of the shader (sss.samples ≤ 101)
} // namespace

PscbfMethod::PscbfMethod(ShaderLibrary& shaders) : shaders_(shaders) {}

glm::dvec3 PscbfMethod::depthSigmaMm(const sss::SssParams& params) {
    const auto variance = sss::skinPscbfProfile(params, sss::pscbfParams(params).sigma).varianceMm2;
    const double scale = sss::profileScale(params.widthMm);
    return {std::sqrt(variance[0]) * scale, std::sqrt(variance[1]) * scale, std::sqrt(variance[2]) * scale};
}

void PscbfMethod::ensureScratch(int width, int height) {
    if (width == width_ && height == height_ && scratch_.get() != 0) return;
    scratch_ = createTexture2D(GL_RGBA32F, width, height);
    width_ = width;
    height_ = height;
}

void PscbfMethod::run(const SssStageInputs& inputs, const sss::SssParams& params, const sss::Kernel& kernel,
                      GLuint output) {
    if (sss::methodInfo(kernel.method).execution != sss::Execution::Pscbf || kernel.stages.size() != 1)
        throw RuntimeError("pscbf method: expected the one-stage pscbf kernel of makeKernel");
    const sss::KernelStage& stage = kernel.stages[0];
    if (stage.taps.empty() || static_cast<int>(stage.taps.size()) > kMaxTaps)
        throw RuntimeError("pscbf method: " + std::to_string(stage.taps.size()) + " taps (supported: 1…101)");
    if (output == inputs.diffuse) throw RuntimeError("pscbf method: output texture must differ from the diffuse input");
    ensureScratch(inputs.width, inputs.height);

    SssExtensionSettings extensions =
        SssExtensionSettings::fromParams(params, inputs.albedo, inputs.aux, inputs.curvature);
    // The spike is what the broad stage's accumulate weights leave (kernel.cpp: accumulate = 1 − spike).
    const glm::vec3 spike(static_cast<float>(1.0 - stage.accumulate[0]), static_cast<float>(1.0 - stage.accumulate[1]),
                          static_cast<float>(1.0 - stage.accumulate[2]));
    const glm::vec3 sigma(depthSigmaMm(params));

    const GLuint scratch = scratch_.get();
    // Framebuffers per run (cheap): the pipeline may recreate `output` between frames.
    const Framebuffer intoScratch = createFramebuffer("pscbf horizontal", &scratch, 1);
    const Framebuffer intoOutput = createFramebuffer("pscbf vertical", &output, 1);

    for (const bool horizontal : {true, false}) {
        ShaderDefines defines = extensions.defines();
        if (!horizontal) defines.emplace_back("PSCBF_FINAL_PASS", "1");
        const GLuint program = shaders_.program("fullscreen.vert", "pscbf_blur.frag", defines);
        setTapUniforms(program, stage);
        setUniform(program, "horizontal", horizontal ? 1 : 0);
        setUniform(program, "focalLengthPixels", inputs.focalLengthPixels);
        setUniform(program, "mmPerUnit", inputs.mmPerUnit);
        setUniform(program, "principalPoint",
                   std::isnan(inputs.principalPoint.x) ? glm::vec2(0.5f * inputs.width, 0.5f * inputs.height)
                                                       : inputs.principalPoint);
        setUniform(program, "worldToView", glm::mat3(inputs.view));
        setUniform(program, "hasGeometricNormal", inputs.geometricNormal != 0 ? 1 : 0);
        setUniform(program, "depthWeight", params.followSurface ? 1 : 0);
        setUniform(program, "depthSigmaMm", sigma);
        setUniform(program, "spike", spike);

        glUseProgram(program);
        glBindFramebuffer(GL_FRAMEBUFFER, horizontal ? intoScratch.get() : intoOutput.get());
        glViewport(0, 0, inputs.width, inputs.height);
        glBindTextureUnit(kSourceUnit, horizontal ? inputs.diffuse : scratch);
        glBindTextureUnit(kDepthUnit, inputs.linearDepth);
        glBindTextureUnit(kNormalUnit, inputs.geometricNormal);
        glBindTextureUnit(kUnblurredUnit, inputs.diffuse);
        extensions.litTexture = horizontal ? inputs.diffuse : scratch; // sss.extension_input = "lit"
        extensions.bind(program, kFirstExtensionUnit);
        shaders_.drawFullscreenTriangle();
        extensions.unbind(kFirstExtensionUnit);
        for (GLuint unit : {kSourceUnit, kDepthUnit, kNormalUnit, kUnblurredUnit}) glBindTextureUnit(unit, 0);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glUseProgram(0);
        checkGl(horizontal ? "pscbf pass (horizontal)" : "pscbf pass (vertical)");
    }
}

} // namespace skinlab::renderer::gl
