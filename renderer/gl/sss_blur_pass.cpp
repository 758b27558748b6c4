#include "renderer/gl/sss_blur_pass.h"

#include "common/error.h"
#include "renderer/gl/shader_checks.h"
#include "renderer/gl/shader_library.h"

#include <glm/glm.hpp>
#include <vector>

namespace skinlab::renderer::gl {

namespace {
// Units 0 and 1 are the source colour and the linear depth (layout(binding) in sss_blur.frag); the extension
// textures take 2, 3, 4, 5.
constexpr GLuint kFirstExtensionTextureUnit = 2;
} // namespace

void setTapUniforms(GLuint program, const sss::KernelStage& stage) {
    std::vector<glm::vec4> taps;
    taps.reserve(stage.taps.size());
    for (const auto& tap : stage.taps)
        taps.emplace_back(static_cast<float>(tap.weight[0]), static_cast<float>(tap.weight[1]),
                          static_cast<float>(tap.weight[2]), static_cast<float>(tap.offsetMm));
    glProgramUniform4fv(program, uniformLocation(program, "taps"), static_cast<GLsizei>(taps.size()), &taps[0].x);
    setUniform(program, "tapCount", static_cast<int>(taps.size()));
}

SssBlurPass::SssBlurPass(ShaderLibrary& shaders) : shaders_(shaders) {}

void SssBlurPass::run(const SssBlurPassInputs& inputs, const sss::KernelStage& stage, bool horizontal, GLuint target,
                      bool accumulate) {
    if (stage.taps.empty() || stage.taps.size() > 101)
        throw RuntimeError("SSS blur pass: " + std::to_string(stage.taps.size()) + " taps (supported: 1…101)");
    ShaderDefines defines = inputs.extensions.defines();
    if (accumulate) defines.emplace_back("SSS_ACCUMULATE", "1");
    const GLuint program = shaders_.program("fullscreen.vert", "sss_blur.frag", defines);
    setTapUniforms(program, stage);
    setUniform(program, "horizontal", horizontal ? 1 : 0);
    setUniform(program, "focalLengthPixels", inputs.focalLengthPixels);
    setUniform(program, "mmPerUnit", inputs.mmPerUnit);
    setUniform(program, "followSurface", inputs.followSurface ? 1 : 0);
    setUniform(program, "followSurfaceK", inputs.followSurfaceK);
    setUniform(program, "accumulateWeight",
               glm::vec3(static_cast<float>(stage.accumulate[0]), static_cast<float>(stage.accumulate[1]),
                         static_cast<float>(stage.accumulate[2])));

    // First of the state changes: it throws (a pipeline bug) before touching any GL state when a switched-on
    // extension has no texture.
    SssExtensionSettings extensions = inputs.extensions;
    extensions.litTexture = inputs.source; // sss.extension_input = "lit": the colour this pass blurs
    extensions.bind(program, kFirstExtensionTextureUnit);
    glUseProgram(program);
    glBindFramebuffer(GL_FRAMEBUFFER, target);
    glViewport(0, 0, inputs.width, inputs.height);
    if (accumulate) {
        // Attachment 1 accumulates Σ_i accumulate_i · stage_i (rgb added); its alpha takes the mask.
        glEnablei(GL_BLEND, 1);
        glBlendFuncSeparatei(1, GL_ONE, GL_ONE, GL_ONE, GL_ZERO);
    }
    glBindTextureUnit(0, inputs.source);
    glBindTextureUnit(1, inputs.linearDepth);
    shaders_.drawFullscreenTriangle();
    glBindTextureUnit(0, 0);
    glBindTextureUnit(1, 0);
    inputs.extensions.unbind(kFirstExtensionTextureUnit);
    if (accumulate) {
        glDisablei(GL_BLEND, 1);
        glBlendFuncSeparatei(1, GL_ONE, GL_ZERO, GL_ONE, GL_ZERO);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
    checkGl(horizontal ? "SSS blur pass (horizontal)" : "SSS blur pass (vertical)");
}

} // namespace skinlab::renderer::gl
