#include "renderer/gl/transmittance_pass.h"

namespace skinlab::renderer::gl {

void TransmittancePass::run(FrameTargets& targets, const TransmittanceSettings& settings) {
    if (!settings.enabled) return;
    // A framebuffer per run: texture names are recycled when the frame is resized (as in the SSS stage).
    const GLuint colours[] = {targets.diffuse.get()};
    const Framebuffer framebuffer = createFramebuffer("transmittance pass", colours, 1);
    const GLuint program = shaders_.program("fullscreen.vert", "transmittance.frag");
    glUseProgram(program);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer.get());
    glViewport(0, 0, targets.width, targets.height);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
    glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_FALSE); // diffuse alpha is the skin mask: keep it
    setUniform(program, "curvatureEnabled", settings.curvature && !settings.thesisForm ? 1 : 0);
    setUniform(program, "curvatureReferenceMm", settings.curvatureReferenceMm);
    setUniform(program, "mmPerUnit", settings.mmPerUnit);
    glBindTextureUnit(0, targets.transmittance.get());
    glBindTextureUnit(1, targets.curvature.get());
    shaders_.drawFullscreenTriangle();
    glBindTextureUnit(0, 0);
    glBindTextureUnit(1, 0);
    glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDisable(GL_BLEND);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
    checkGl("transmittance pass");
}

} // namespace skinlab::renderer::gl
