#include "renderer/gl/egl_context.h"

#include "common/error.h"

#include <epoxy/egl.h>

#include <epoxy/gl.h>
#include <spdlog/spdlog.h>
#include <string_view>
#include <vector>

namespace skinlab::renderer::gl {

std::string eglErrorName(int error) {
    switch (error) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
    case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
    default: return "EGL error 0x" + std::to_string(error);
    }
}

namespace {

bool hasExtension(const char* extensions, std::string_view name) {
    if (!extensions) return false;
    std::string_view all(extensions);
    std::size_t pos = 0;
    while ((pos = all.find(name, pos)) != std::string_view::npos) {
        const bool startOk = pos == 0 || all[pos - 1] == ' ';
        const bool endOk = pos + name.size() == all.size() || all[pos + name.size()] == ' ';
        if (startOk && endOk) return true;
        pos += name.size();
    }
    return false;
}

// Initialises `display`, binds OpenGL and creates a 4.5 core context without a surface (EGL_KHR_surfaceless_context).
// Returns the context, or nullptr with `failure` naming the EGL call and error.
EGLContext createContext(EGLDisplay display, std::string& failure) {
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor)) {
        failure = "eglInitialize: " + eglErrorName(eglGetError());
        return EGL_NO_CONTEXT;
    }
    if (!eglBindAPI(EGL_OPENGL_API)) {
        failure = "eglBindAPI(EGL_OPENGL_API): " + eglErrorName(eglGetError());
        eglTerminate(display);
        return EGL_NO_CONTEXT;
    }
    const EGLint configAttributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                       EGL_NONE};
    EGLConfig config = nullptr;
    EGLint count = 0;
    // Surfaceless contexts need no config (EGL_KHR_no_config_context); use one if available, else none.
    if (!eglChooseConfig(display, configAttributes, &config, 1, &count) || count == 0) config = EGL_NO_CONFIG_KHR;
    const EGLint contextAttributes[] = {
        EGL_CONTEXT_MAJOR_VERSION,           4,       EGL_CONTEXT_MINOR_VERSION, 5, EGL_CONTEXT_OPENGL_PROFILE_MASK,
        EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, contextAttributes);
    if (context == EGL_NO_CONTEXT) {
        failure = "eglCreateContext(OpenGL 4.5 core): " + eglErrorName(eglGetError());
        eglTerminate(display);
        return EGL_NO_CONTEXT;
    }
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
        failure = "eglMakeCurrent(no surface): " + eglErrorName(eglGetError());
        eglDestroyContext(display, context);
        eglTerminate(display);
        return EGL_NO_CONTEXT;
    }
    return context;
}

} // namespace

EglContext::EglContext() {
    std::vector<std::string> attempts;
    const char* clientExtensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!clientExtensions) {
        throw RuntimeError("no usable EGL: eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS) failed (" +
                           eglErrorName(eglGetError()) +
                           "); install Debian's libegl1 libegl-mesa0 libgl1-mesa-dri for Mesa's llvmpipe");
    }
    auto getPlatformDisplay =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));

    // 1. EGL device platform: a GPU driver's device without a window system (NVIDIA). Mesa also lists a
    //    software device (EGL_MESA_device_software) here; skip it so llvmpipe comes through the surfaceless path.
    if (getPlatformDisplay && hasExtension(clientExtensions, "EGL_EXT_platform_device") &&
        hasExtension(clientExtensions, "EGL_EXT_device_enumeration")) {
        auto queryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
        auto queryDeviceString =
            reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
        EGLDeviceEXT devices[16];
        EGLint deviceCount = 0;
        if (queryDevices && queryDevices(16, devices, &deviceCount)) {
            int hardwareDevices = 0;
            for (EGLint i = 0; i < deviceCount && !context_; ++i) {
                const char* deviceExtensions =
                    queryDeviceString ? queryDeviceString(devices[i], EGL_EXTENSIONS) : nullptr;
                if (hasExtension(deviceExtensions, "EGL_MESA_device_software")) continue;
                ++hardwareDevices;
                EGLDisplay display = getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
                if (display == EGL_NO_DISPLAY) {
                    attempts.push_back("device " + std::to_string(i) +
                                       ": eglGetPlatformDisplayEXT: " + eglErrorName(eglGetError()));
                    continue;
                }
                std::string failure;
                EGLContext context = createContext(display, failure);
                if (context == EGL_NO_CONTEXT) {
                    attempts.push_back("device " + std::to_string(i) + ": " + failure);
                    continue;
                }
                display_ = display;
                context_ = context;
                platform_ = "device";
            }
            if (hardwareDevices == 0) attempts.push_back("device platform: no hardware EGL device");
        } else {
            attempts.push_back("device platform: eglQueryDevicesEXT: " + eglErrorName(eglGetError()));
        }
    } else {
        attempts.push_back("device platform: EGL_EXT_platform_device not supported");
    }

    // 2. Mesa's surfaceless platform: llvmpipe when no GPU driver is present.
    if (!context_) {
        if (getPlatformDisplay && hasExtension(clientExtensions, "EGL_MESA_platform_surfaceless")) {
            EGLDisplay display = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
            if (display == EGL_NO_DISPLAY) {
                attempts.push_back("surfaceless platform: eglGetPlatformDisplayEXT: " + eglErrorName(eglGetError()));
            } else {
                std::string failure;
                EGLContext context = createContext(display, failure);
                if (context == EGL_NO_CONTEXT) {
                    attempts.push_back("surfaceless platform: " + failure);
                } else {
                    display_ = display;
                    context_ = context;
                    platform_ = "surfaceless";
                }
            }
        } else {
            attempts.push_back("surfaceless platform: EGL_MESA_platform_surfaceless not supported");
        }
    }

    if (!context_) {
        std::string message = "no usable EGL OpenGL 4.5 core context; tried ";
        for (std::size_t i = 0; i < attempts.size(); ++i) message += (i ? "; " : "") + attempts[i];
        message += ". Debian's libegl-mesa0 and libgl1-mesa-dri provide the surfaceless platform (llvmpipe)";
        throw RuntimeError(message);
    }
    renderer_ = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    version_ = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    spdlog::info("EGL {} platform: GL_RENDERER {}, GL_VERSION {}", platform_, renderer_, version_);
}

// The display is not terminated: EGL displays are shared per platform within a process and eglTerminate is not
// reference-counted, so terminating here would break any other live context (e.g. a second Renderer).
EglContext::~EglContext() {
    if (context_) {
        eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(display_, context_);
    }
}

void EglContext::makeCurrent() {
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
        throw RuntimeError("eglMakeCurrent: " + eglErrorName(eglGetError()));
}

} // namespace skinlab::renderer::gl
