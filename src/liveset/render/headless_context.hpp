// An OpenGL 3.3 core context without any window system, for `liveset view --headless`, scripted
// screenshots, the demo without a display and the rendering tests: EGL on Mesa's surfaceless
// platform (EGL_PLATFORM_SURFACELESS_MESA), or on an EGL device (EGL_PLATFORM_DEVICE_EXT: the
// NVIDIA driver on a headless GPU server). Draw into a Framebuffer; there is no default framebuffer.
#pragma once

#include <string>

namespace liveset::render {

enum class EglPlatform {
    kAutomatic,  // surfaceless where EGL offers it, else the first EGL device (hardware before software)
    kDevice,     // an enumerated EGL device only (hardware before software)
};

class HeadlessContext {
public:
    // Creates the context and makes it current on this thread. Throws std::runtime_error with a
    // one-line reason ("cannot create a headless OpenGL context: ...") when EGL, the platform or
    // an OpenGL 3.3 core context is unavailable.
    explicit HeadlessContext(EglPlatform platform = EglPlatform::kAutomatic);
    ~HeadlessContext();
    HeadlessContext(const HeadlessContext&) = delete;
    HeadlessContext& operator=(const HeadlessContext&) = delete;

    void make_current();
    // The platform the context was made on: "surfaceless" or "device".
    const char* platform() const { return platform_; }

private:
    bool try_display(void* display);

    void* display_ = nullptr;
    void* context_ = nullptr;
    const char* platform_ = "";
};

// "llvmpipe (LLVM 15.0.6, 256 bits), 4.5 (Core Profile) Mesa 22.3.6" for the current context.
std::string describe_current_context();

}  // namespace liveset::render
