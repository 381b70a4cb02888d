// EGL surfaceless context creation.
#include "liveset/render/headless_context.hpp"

#include "liveset/render/driver_allocations.hpp"

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <cstring>
#include <stdexcept>

namespace liveset::render {

namespace {

[[noreturn]] void fail(const std::string& why) { throw std::runtime_error("cannot create a headless OpenGL context: " + why); }

bool has_client_extension(const char* name) {
    const char* all = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (all == nullptr) return false;
    const std::size_t n = std::strlen(name);
    for (const char* p = std::strstr(all, name); p != nullptr; p = std::strstr(p + 1, name))
        if ((p == all || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
    return false;
}

}  // namespace

HeadlessContext::HeadlessContext() {
    keep_driver_mapped();
    if (!has_client_extension("EGL_MESA_platform_surfaceless") || !has_client_extension("EGL_EXT_platform_base"))
        fail("EGL lacks the surfaceless platform (install Mesa: libegl1, libgl1-mesa-dri)");
    // The EXT entry point: eglGetPlatformDisplay through epoxy aborts before any display exists.
    EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (display == EGL_NO_DISPLAY) fail("no surfaceless EGL display");
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor)) fail("eglInitialize failed");
    display_ = display;
    if (!eglBindAPI(EGL_OPENGL_API)) {
        eglTerminate(display);
        fail("EGL cannot bind desktop OpenGL");
    }
    // Surfaceless configurations are pbuffer-capable (the default, window, matches none).
    const EGLint config_attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint configs = 0;
    if (!eglChooseConfig(display, config_attributes, &config, 1, &configs) || configs < 1) {
        eglTerminate(display);
        fail("no EGL configuration for desktop OpenGL");
    }
    const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                                         EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attributes);
    if (context == EGL_NO_CONTEXT) {
        eglTerminate(display);
        fail("no OpenGL 3.3 core context");
    }
    context_ = context;
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
        eglDestroyContext(display, context);
        eglTerminate(display);
        fail("cannot make the context current without a surface");
    }
}

HeadlessContext::~HeadlessContext() {
    if (display_ == nullptr) return;
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (context_ != nullptr) eglDestroyContext(display_, context_);
    eglTerminate(display_);
}

void HeadlessContext::make_current() {
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
        throw std::runtime_error("cannot make the headless OpenGL context current");
}

std::string describe_current_context() {
    const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    return std::string(renderer ? renderer : "?") + ", " + (version ? version : "?");
}

}  // namespace liveset::render
