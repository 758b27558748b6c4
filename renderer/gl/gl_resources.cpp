#include "renderer/gl/gl_resources.h"

#include "common/error.h"

#include <vector>

namespace skinlab::renderer::gl {

std::string glErrorName(GLenum error) {
    switch (error) {
    case GL_NO_ERROR: return "GL_NO_ERROR";
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    default: return "GL error 0x" + std::to_string(error);
    }
}

void checkGl(std::string_view where) {
    const GLenum error = glGetError();
    if (error == GL_NO_ERROR) return;
    // Drain further queued errors so the next check reports its own.
    while (glGetError() != GL_NO_ERROR) {
    }
    throw RuntimeError(glErrorName(error) + " after " + std::string(where));
}

void deleteTexture(GLuint name) { glDeleteTextures(1, &name); }
void deleteFramebuffer(GLuint name) { glDeleteFramebuffers(1, &name); }
void deleteBuffer(GLuint name) { glDeleteBuffers(1, &name); }
void deleteVertexArray(GLuint name) { glDeleteVertexArrays(1, &name); }
void deleteProgram(GLuint name) { glDeleteProgram(name); }
void deleteQuery(GLuint name) { glDeleteQueries(1, &name); }

Texture createTexture2D(GLenum internalFormat, int width, int height, int levels) {
    GLuint name = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &name);
    Texture texture(name);
    glTextureStorage2D(name, levels, internalFormat, width, height);
    glTextureParameteri(name, GL_TEXTURE_MIN_FILTER, levels > 1 ? GL_LINEAR_MIPMAP_LINEAR : GL_NEAREST);
    glTextureParameteri(name, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTextureParameteri(name, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(name, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    checkGl("creating a " + std::to_string(width) + "x" + std::to_string(height) + " texture");
    return texture;
}

Framebuffer createFramebuffer(std::string_view label, const GLuint* colours, int colourCount, GLuint depth) {
    GLuint name = 0;
    glCreateFramebuffers(1, &name);
    Framebuffer framebuffer(name);
    std::vector<GLenum> drawBuffers;
    for (int i = 0; i < colourCount; ++i) {
        glNamedFramebufferTexture(name, GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i), colours[i], 0);
        drawBuffers.push_back(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i));
    }
    if (depth) glNamedFramebufferTexture(name, GL_DEPTH_ATTACHMENT, depth, 0);
    if (drawBuffers.empty()) glNamedFramebufferDrawBuffer(name, GL_NONE);
    else glNamedFramebufferDrawBuffers(name, static_cast<GLsizei>(drawBuffers.size()), drawBuffers.data());
    const GLenum status = glCheckNamedFramebufferStatus(name, GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE)
        throw RuntimeError(std::string(label) + ": framebuffer incomplete (status 0x" + std::to_string(status) + ")");
    checkGl(std::string("creating framebuffer ") + std::string(label));
    return framebuffer;
}

} // namespace skinlab::renderer::gl
