// An OpenGL 3.3 core context without any window system: EGL on Mesa's surfaceless platform
// (EGL_PLATFORM_SURFACELESS_MESA through eglGetPlatformDisplayEXT), for `liveset view --headless`,
// scripted screenshots, the demo without a display and the rendering tests. Draw into a
// Framebuffer; there is no default framebuffer.
#pragma once

#include <string>

namespace liveset::render {

class HeadlessContext {
public:
    // Creates the context and makes it current on this thread. Throws std::runtime_error with a
    // one-line reason ("cannot create a headless OpenGL context: ...") when EGL, the surfaceless
    // platform or an OpenGL 3.3 core context is unavailable.
    HeadlessContext();
    ~HeadlessContext();
    HeadlessContext(const HeadlessContext&) = delete;
    HeadlessContext& operator=(const HeadlessContext&) = delete;

    void make_current();

private:
    void* display_ = nullptr;
    void* context_ = nullptr;
};

// "llvmpipe (LLVM 15.0.6, 256 bits), 4.5 (Core Profile) Mesa 22.3.6" for the current context.
std::string describe_current_context();

}  // namespace liveset::render
