#include "renderer/gl/resolve_pass.h"

#include "common/error.h"

namespace skinlab::renderer::gl {

void ResolvePass::run(const FrameTargets& internal, GLuint source, FrameTargets& output, GLuint destination, int factor,
                      ResolveMode mode) {
    if (internal.width != output.width * factor || internal.height != output.height * factor)
        throw RuntimeError("resolve pass: internal targets " + std::to_string(internal.width) + "x" +
                           std::to_string(internal.height) + " are not " + std::to_string(factor) + " x the output " +
                           std::to_string(output.width) + "x" + std::to_string(output.height));
    const GLuint colours[] = {destination};
    const Framebuffer framebuffer = createFramebuffer("resolve pass", colours, 1);
    const GLuint program = shaders_.program("fullscreen.vert", "resolve.frag");
    glUseProgram(program);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer.get());
    glViewport(0, 0, output.width, output.height);
    setUniform(program, "factor", factor);
    setUniform(program, "mode", static_cast<int>(mode));
    glBindTextureUnit(0, source);
    glBindTextureUnit(1, internal.linearDepth.get());
    shaders_.drawFullscreenTriangle();
    glBindTextureUnit(0, 0);
    glBindTextureUnit(1, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
    checkGl("resolve pass");
}

} // namespace skinlab::renderer::gl
