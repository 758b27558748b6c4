#include "renderer/gl/add_specular_pass.h"

namespace skinlab::renderer::gl {

void AddSpecularPass::run(FrameTargets& targets) {
    const GLuint program = shaders_.program("fullscreen.vert", "add_specular.frag");
    glUseProgram(program);
    glBindFramebuffer(GL_FRAMEBUFFER, targets.beautyFramebuffer.get());
    glViewport(0, 0, targets.width, targets.height);
    glBindTextureUnit(0, targets.scatteredDiffuse.get());
    glBindTextureUnit(1, targets.specular.get());
    shaders_.drawFullscreenTriangle();
    glBindTextureUnit(0, 0);
    glBindTextureUnit(1, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
    checkGl("add specular pass");
}

} // namespace skinlab::renderer::gl
