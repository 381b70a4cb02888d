// EGL context creation without a window system: the surfaceless platform, else an EGL device.
#include "liveset/render/headless_context.hpp"

#include "liveset/render/driver_allocations.hpp"

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace liveset::render {

namespace {

[[noreturn]] void fail(const std::string& why) { throw std::runtime_error("cannot create a headless OpenGL context: " + why); }

bool has_extension(const char* all, const char* name) {
    if (all == nullptr) return false;
    const std::size_t n = std::strlen(name);
    for (const char* p = std::strstr(all, name); p != nullptr; p = std::strstr(p + 1, name))
        if ((p == all || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
    return false;
}

// The EGL devices, hardware first (Mesa's software device says EGL_MESA_device_software), each
// group in the driver's order; the driver's order alone where devices cannot be queried.
std::vector<EGLDeviceEXT> devices_hardware_first(bool can_query) {
    EGLint n = 0;
    if (!eglQueryDevicesEXT(0, nullptr, &n) || n <= 0) return {};
    std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(n));
    if (!eglQueryDevicesEXT(n, devices.data(), &n)) return {};
    devices.resize(static_cast<std::size_t>(std::max(n, 0)));
    if (!can_query) return devices;
    std::stable_partition(devices.begin(), devices.end(), [](EGLDeviceEXT d) {
        return !has_extension(eglQueryDeviceStringEXT(d, EGL_EXTENSIONS), "EGL_MESA_device_software");
    });
    return devices;
}

}  // namespace

// Initialises `display` and makes a current OpenGL 3.3 core context on it; on failure leaves
// nothing behind and returns false.
bool HeadlessContext::try_display(void* native) {
    auto display = static_cast<EGLDisplay>(native);
    if (display == EGL_NO_DISPLAY) return false;
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor)) return false;
    // pbuffer-capable configurations (the default, window, matches none without a window system)
    const EGLint config_attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                                         EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint configs = 0;
    EGLContext context = EGL_NO_CONTEXT;
    if (eglBindAPI(EGL_OPENGL_API) && eglChooseConfig(display, config_attributes, &config, 1, &configs) && configs >= 1)
        context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attributes);
    if (context != EGL_NO_CONTEXT && eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
        display_ = display;
        context_ = context;
        return true;
    }
    if (context != EGL_NO_CONTEXT) eglDestroyContext(display, context);
    eglTerminate(display);
    return false;
}

HeadlessContext::HeadlessContext(EglPlatform platform) {
    keep_driver_mapped();
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    const auto has = [&](const char* name) { return has_extension(client, name); };
    const bool base = has("EGL_EXT_platform_base");
    const bool surfaceless = base && has("EGL_MESA_platform_surfaceless");
    const bool device = base && has("EGL_EXT_platform_device") && (has("EGL_EXT_device_enumeration") || has("EGL_EXT_device_base"));
    // The EXT entry point: eglGetPlatformDisplay through epoxy aborts before any display exists.
    if (platform == EglPlatform::kAutomatic && surfaceless &&
        try_display(eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr))) {
        platform_ = "surfaceless";
        return;
    }
    if (device) {
        for (EGLDeviceEXT d : devices_hardware_first(has("EGL_EXT_device_query") || has("EGL_EXT_device_base"))) {
            if (try_display(eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, d, nullptr))) {
                platform_ = "device";
                return;
            }
        }
    }
    if (platform == EglPlatform::kDevice && !device) fail("EGL lacks the device platform (EGL_EXT_platform_device)");
    if (!surfaceless && !device)
        fail("EGL offers neither the surfaceless nor the device platform (install Mesa: libegl1, libgl1-mesa-dri; or a GPU driver)");
    fail("no EGL display gives an OpenGL 3.3 core context without a surface");
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
