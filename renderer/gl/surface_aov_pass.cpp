#include "renderer/gl/surface_aov_pass.h"

namespace skinlab::renderer::gl {

void SurfaceAovPass::run(FrameTargets& targets, const SurfaceAovSettings& settings) {
    if (targets.width != width_ || targets.height != height_ || !rawCurvature_.get()) {
        rawCurvature_ = createTexture2D(GL_RG32F, targets.width, targets.height);
        smoothedAlongX_ = createTexture2D(GL_RG32F, targets.width, targets.height);
        width_ = targets.width;
        height_ = targets.height;
    }
    // Framebuffers per run: texture names are recycled when the frame is resized (as in the SSS stage).
    const GLuint firstColours[] = {targets.aux.get(), rawCurvature_.get()};
    const Framebuffer first = createFramebuffer("surface AOV pass", firstColours, 2);
    const GLuint alongXColours[] = {smoothedAlongX_.get()};
    const Framebuffer alongX = createFramebuffer("curvature smoothing along x", alongXColours, 1);
    const GLuint alongYColours[] = {targets.curvature.get()};
    const Framebuffer alongY = createFramebuffer("curvature smoothing along y", alongYColours, 1);
    const glm::vec2 viewport(static_cast<float>(targets.width), static_cast<float>(targets.height));
    glViewport(0, 0, targets.width, targets.height);

    // 1. aux.Y and the raw curvature.
    GLuint program = shaders_.program("fullscreen.vert", "surface_aovs.frag");
    glUseProgram(program);
    glBindFramebuffer(GL_FRAMEBUFFER, first.get());
    const glm::mat4& projection = settings.camera.projection;
    setUniform(program, "ndcToView",
               glm::vec4(1.0f / projection[0][0], 1.0f / projection[1][1], projection[2][0] / projection[0][0],
                         projection[2][1] / projection[1][1]));
    setUniform(program, "viewFromWorld", glm::mat3(settings.camera.view));
    setUniform(program, "viewportSize", viewport);
    setUniform(program, "focalLengthPixels", settings.camera.focalLengthPixels);
    setUniform(program, "depthStepPixels", kSurfaceDepthStepPixels);
    setUniform(program, "axisCount", 2);
    setUniform(program, "screenCurvature", settings.screenCurvature ? 1 : 0);
    glBindTextureUnit(0, targets.linearDepth.get());
    glBindTextureUnit(1, targets.geometricNormal.get());
    glBindTextureUnit(2, targets.albedo.get());
    glBindTextureUnit(3, targets.mask.get());
    shaders_.drawFullscreenTriangle();

    // 2. Depth-aware smoothing of the curvature on skin, along x then along y.
    program = shaders_.program("fullscreen.vert", "curvature_smooth.frag");
    glUseProgram(program);
    setUniform(program, "focalLengthPixels", settings.camera.focalLengthPixels);
    setUniform(program, "depthStepPixels", kSurfaceDepthStepPixels);
    setUniform(program, "radius", kCurvatureSmoothingRadius);
    glBindFramebuffer(GL_FRAMEBUFFER, alongX.get());
    setUniform(program, "direction", glm::vec2(1.0f, 0.0f));
    setUniform(program, "finalPass", 0);
    glBindTextureUnit(0, rawCurvature_.get());
    shaders_.drawFullscreenTriangle();
    glBindFramebuffer(GL_FRAMEBUFFER, alongY.get());
    setUniform(program, "direction", glm::vec2(0.0f, 1.0f));
    setUniform(program, "finalPass", 1);
    glBindTextureUnit(0, smoothedAlongX_.get());
    shaders_.drawFullscreenTriangle();

    for (GLuint unit = 0; unit < 4; ++unit) glBindTextureUnit(unit, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
    checkGl("surface AOV pass");
}

} // namespace skinlab::renderer::gl
