#include "renderer/gl/frame_targets.h"

#include <cstring>
#include <limits>
#include <vector>

namespace skinlab::renderer::gl {

void FrameTargets::resize(int newWidth, int newHeight) {
    if (newWidth == width && newHeight == height && diffuse.get()) return;
    width = newWidth;
    height = newHeight;
    diffuse = createTexture2D(GL_RGBA32F, width, height);
    specular = createTexture2D(GL_RGBA32F, width, height);
    albedo = createTexture2D(GL_RGBA32F, width, height);
    linearDepth = createTexture2D(GL_R32F, width, height);
    normal = createTexture2D(GL_RGBA32F, width, height);
    geometricNormal = createTexture2D(GL_RGBA32F, width, height);
    mask = createTexture2D(GL_R32F, width, height);
    transmittance = createTexture2D(GL_RGBA32F, width, height);
    aux = createTexture2D(GL_R32F, width, height);
    curvature = createTexture2D(GL_R32F, width, height);
    depthBuffer = createTexture2D(GL_DEPTH_COMPONENT32F, width, height);
    scatteredDiffuse = createTexture2D(GL_RGBA32F, width, height);
    beauty = createTexture2D(GL_RGBA32F, width, height);
    display = createTexture2D(GL_RGBA32F, width, height);
    const GLuint mainColours[] = {diffuse.get(), specular.get(),        albedo.get(), linearDepth.get(),
                                  normal.get(),  geometricNormal.get(), mask.get(),   transmittance.get()};
    mainFramebuffer = createFramebuffer("main pass", mainColours, 8, depthBuffer.get());
    const GLuint backgroundColours[] = {diffuse.get()};
    backgroundFramebuffer = createFramebuffer("background pass", backgroundColours, 1, depthBuffer.get());
    const GLuint beautyColours[] = {beauty.get()};
    beautyFramebuffer = createFramebuffer("add specular pass", beautyColours, 1);
    const GLuint displayColours[] = {display.get()};
    displayFramebuffer = createFramebuffer("tone map pass", displayColours, 1);
}

void FrameTargets::clear() {
    const float zero[4] = {0, 0, 0, 0};
    const float infinite[4] = {std::numeric_limits<float>::infinity(), 0, 0, 0};
    const float far = 1.0f;
    for (GLint i = 0; i < 8; ++i)
        glClearNamedFramebufferfv(mainFramebuffer.get(), GL_COLOR, i, i == 3 ? infinite : zero);
    glClearTexImage(aux.get(), 0, GL_RED, GL_FLOAT, zero);
    glClearTexImage(curvature.get(), 0, GL_RED, GL_FLOAT, zero);
    glClearNamedFramebufferfv(mainFramebuffer.get(), GL_DEPTH, 0, &far);
    checkGl("clearing the frame");
}

void readTexture(GLuint texture, int width, int height, int channels, float* out) {
    const GLenum format = channels == 1 ? GL_RED : channels == 2 ? GL_RG : channels == 3 ? GL_RGB : GL_RGBA;
    const std::size_t rowFloats = static_cast<std::size_t>(width) * static_cast<std::size_t>(channels);
    std::vector<float> bottomUp(rowFloats * static_cast<std::size_t>(height));
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glGetTextureImage(texture, 0, format, GL_FLOAT, static_cast<GLsizei>(bottomUp.size() * sizeof(float)),
                      bottomUp.data());
    checkGl("reading back a texture");
    for (int y = 0; y < height; ++y)
        std::memcpy(out + static_cast<std::size_t>(y) * rowFloats,
                    bottomUp.data() + static_cast<std::size_t>(height - 1 - y) * rowFloats, rowFloats * sizeof(float));
}

} // namespace skinlab::renderer::gl
