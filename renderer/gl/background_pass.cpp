#include "renderer/gl/background_pass.h"

namespace skinlab::renderer::gl {

void BackgroundPass::run(FrameTargets& targets, const BackgroundSettings& settings) {
    const GLuint program = shaders_.program("fullscreen.vert", "background.frag");
    glUseProgram(program);
    glBindFramebuffer(GL_FRAMEBUFFER, targets.backgroundFramebuffer.get());
    glViewport(0, 0, targets.width, targets.height);
    // The triangle lies on the far plane: it passes only where the depth buffer still holds its clear value.
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_FALSE);
    setUniform(program, "useEnvironment", settings.environmentMap ? 1 : 0);
    setUniform(program, "backgroundColor", settings.color);
    setUniform(program, "environmentIntensity", settings.environmentIntensity);
    setUniform(program, "exposure", settings.exposure);
    setUniform(program, "inverseViewProjection", glm::inverse(settings.camera.projection * settings.camera.view));
    setUniform(program, "cameraPosition", settings.camera.position);
    setUniform(program, "environmentFromWorld", settings.environmentFromWorld);
    glBindTextureUnit(0, settings.environmentMap);
    shaders_.drawFullscreenTriangle();
    glBindTextureUnit(0, 0);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    glDisable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
    checkGl("background pass");
}

} // namespace skinlab::renderer::gl
