#include "renderer/gl/tone_map_pass.h"

#include "common/error.h"

namespace skinlab::renderer::gl {

int toneMapperIndex(const std::string& toneMapper) {
    if (toneMapper == "linear") return 0;
    if (toneMapper == "exponential") return 1;
    if (toneMapper == "reinhard-rgb") return 2;
    if (toneMapper == "filmic") return 3;
    if (toneMapper == "reinhard") return 4;
    throw InputError("tone_map.operator: '" + toneMapper +
                     "' is not one of: linear, exponential, reinhard, reinhard-rgb, filmic");
}

void ToneMapPass::run(FrameTargets& targets, const std::string& toneMapper, float exponentialK, float filmicWhite,
                      float reinhardScale) {
    const GLuint program = shaders_.program("fullscreen.vert", "tone_map.frag");
    glUseProgram(program);
    glBindFramebuffer(GL_FRAMEBUFFER, targets.displayFramebuffer.get());
    glViewport(0, 0, targets.width, targets.height);
    setUniform(program, "operatorIndex", toneMapperIndex(toneMapper));
    setUniform(program, "exponentialK", exponentialK);
    setUniform(program, "filmicWhite", filmicWhite);
    setUniform(program, "reinhardScale", reinhardScale);
    glBindTextureUnit(0, targets.beauty.get());
    shaders_.drawFullscreenTriangle();
    glBindTextureUnit(0, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
    checkGl("tone map pass");
}

} // namespace skinlab::renderer::gl
