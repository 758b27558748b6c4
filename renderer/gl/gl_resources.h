#pragma once
// Owning wrappers of GL objects (one name each, deleted on destruction, movable) and the GL error check.
// All need a current context (EglContext).
#include <epoxy/gl.h>
#include <string>
#include <string_view>
#include <utility>

namespace skinlab::renderer::gl {

// Throws RuntimeError "GL error GL_INVALID_OPERATION after <where>" when glGetError reports one.
void checkGl(std::string_view where);
std::string glErrorName(GLenum error);

// Generic owner of one GL name with a deleter.
template <void (*Delete)(GLuint)>
class GlName {
public:
    GlName() = default;
    explicit GlName(GLuint name) : name_(name) {}
    ~GlName() { reset(); }
    GlName(GlName&& other) noexcept : name_(std::exchange(other.name_, 0)) {}
    GlName& operator=(GlName&& other) noexcept {
        if (this != &other) {
            reset();
            name_ = std::exchange(other.name_, 0);
        }
        return *this;
    }
    GlName(const GlName&) = delete;
    GlName& operator=(const GlName&) = delete;
    GLuint get() const { return name_; }
    void reset() {
        if (name_) Delete(name_);
        name_ = 0;
    }

private:
    GLuint name_ = 0;
};

void deleteTexture(GLuint name);
void deleteFramebuffer(GLuint name);
void deleteBuffer(GLuint name);
void deleteVertexArray(GLuint name);
void deleteProgram(GLuint name);
void deleteQuery(GLuint name);

using Texture = GlName<deleteTexture>;
using Framebuffer = GlName<deleteFramebuffer>;
using Buffer = GlName<deleteBuffer>;
using VertexArray = GlName<deleteVertexArray>;
using Program = GlName<deleteProgram>;
using Query = GlName<deleteQuery>;

// Immutable 2-D texture (glTextureStorage2D), nearest filtering, clamped; `levels` > 1 for mipmaps.
Texture createTexture2D(GLenum internalFormat, int width, int height, int levels = 1);
// Framebuffer with the given colour attachments (attachment i = colours[i]) and optional depth texture;
// enables all colour attachments as draw buffers and checks completeness (RuntimeError naming `label`).
Framebuffer createFramebuffer(std::string_view label, const GLuint* colours, int colourCount, GLuint depth = 0);

} // namespace skinlab::renderer::gl
