#pragma once
// A headless OpenGL 4.5 core context through EGL, no window system (design.md "Rendering on any machine").
// Tried in order: the EGL device platform (EGL_EXT_platform_device, e.g. NVIDIA), then Mesa's surfaceless
// platform (EGL_MESA_platform_surfaceless → llvmpipe on the CPU). All rendering goes to framebuffer objects.
#include <string>

namespace skinlab::renderer::gl {

class EglContext {
public:
    // Creates the context and makes it current on the calling thread. Throws RuntimeError naming every platform
    // tried, the EGL error of each, and the Debian packages that provide a working one.
    EglContext();
    ~EglContext();
    EglContext(const EglContext&) = delete;
    EglContext& operator=(const EglContext&) = delete;

    void makeCurrent();
    const std::string& renderer() const { return renderer_; } // GL_RENDERER
    const std::string& version() const { return version_; }   // GL_VERSION
    const std::string& platform() const { return platform_; } // "device" or "surfaceless"

private:
    void* display_ = nullptr; // EGLDisplay
    void* context_ = nullptr; // EGLContext
    std::string renderer_;
    std::string version_;
    std::string platform_;
};

// Human-readable name of an EGL error code ("EGL_BAD_MATCH").
std::string eglErrorName(int error);

} // namespace skinlab::renderer::gl
