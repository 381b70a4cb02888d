// GLFW window loop.
#include "window_app.hpp"

#include <epoxy/gl.h>
// epoxy provides the GL declarations; GLFW must not include its own.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <fmt/core.h>

#include <chrono>
#include <cstdlib>

#include "cli_common.hpp"
#include "liveset/render/driver_allocations.hpp"
#include "script_player.hpp"

namespace liveset::viewer {

namespace {

std::string g_glfw_error;

void on_glfw_error(int, const char* description) { g_glfw_error = description ? description : "unknown GLFW error"; }

Viewer& viewer_of(GLFWwindow* w) { return *static_cast<Viewer*>(glfwGetWindowUserPointer(w)); }

// Window coordinates -> framebuffer pixels (they differ on high-DPI screens).
void scaled_cursor(GLFWwindow* w, double& x, double& y) {
    int ww = 1, wh = 1, fw = 1, fh = 1;
    glfwGetWindowSize(w, &ww, &wh);
    glfwGetFramebufferSize(w, &fw, &fh);
    x *= static_cast<double>(fw) / std::max(ww, 1);
    y *= static_cast<double>(fh) / std::max(wh, 1);
}

// Where the pointer was when the event being handled happened: the last position the cursor
// callback delivered (events come in order). glfwGetCursorPos asks the X server where the pointer
// is now, which, while the viewer is busy and events wait in the queue, is further along a drag:
// a press read that way started the drag late and lost its first moves (a pan fell short).
struct Pointer {
    double x = 0, y = 0;
    bool known = false;  // no cursor event yet (the pointer has not moved in the window)
};
Pointer g_pointer;

void pointer_at_event(GLFWwindow* w, double& x, double& y) {
    if (g_pointer.known) {
        x = g_pointer.x;
        y = g_pointer.y;
    } else {
        glfwGetCursorPos(w, &x, &y);
    }
}

void on_cursor(GLFWwindow* w, double x, double y) {
    g_pointer = {x, y, true};
    scaled_cursor(w, x, y);
    viewer_of(w).push_event({InputEvent::Type::kMove, x, y});
}

void on_button(GLFWwindow* w, int button, int action, int mods) {
    double x = 0, y = 0;
    pointer_at_event(w, x, y);
    scaled_cursor(w, x, y);
    InputEvent e{action == GLFW_PRESS ? InputEvent::Type::kPress : InputEvent::Type::kRelease, x, y};
    e.button = button;
    e.mods = mods;
    viewer_of(w).push_event(e);
}

void on_scroll(GLFWwindow* w, double, double dy) {
    double x = 0, y = 0;
    pointer_at_event(w, x, y);
    scaled_cursor(w, x, y);
    InputEvent e{InputEvent::Type::kScroll, x, y};
    e.scroll = dy;
    if (glfwGetKey(w, GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS || glfwGetKey(w, GLFW_KEY_RIGHT_CONTROL) == GLFW_PRESS)
        e.mods |= GLFW_MOD_CONTROL;  // GLFW gives a wheel event no modifiers: Ctrl+wheel zooms a slice
    viewer_of(w).push_event(e);
}

void on_key(GLFWwindow* w, int key, int, int action, int mods) {
    InputEvent e{InputEvent::Type::kKey};
    e.key = key;
    e.mods = mods;
    e.down = action != GLFW_RELEASE;
    viewer_of(w).push_event(e);
}

void on_char(GLFWwindow* w, unsigned codepoint) {
    InputEvent e{InputEvent::Type::kChar};
    e.codepoint = codepoint;
    viewer_of(w).push_event(e);
}

void on_refresh(GLFWwindow* w) { viewer_of(w).request_redraw(); }

}  // namespace

bool display_available() {
    const char* d = std::getenv("DISPLAY");
    const char* wl = std::getenv("WAYLAND_DISPLAY");
    return (d && *d) || (wl && *wl);
}

int run_window(std::unique_ptr<Session> session, const std::string& image_name, const ViewerConfig& config,
               const WindowOptions& options, const std::function<void(Viewer&)>& prepare) {
    glfwSetErrorCallback(on_glfw_error);
    render::keep_driver_mapped();
    if (!glfwInit()) throw cli::UsageError("cannot open a window: " + g_glfw_error + " (use --headless without a display)");
    struct Terminate {
        ~Terminate() { glfwTerminate(); }
    } terminate;
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    GLFWwindow* window = glfwCreateWindow(options.width, options.height, options.title.c_str(), nullptr, nullptr);
    if (!window) throw cli::UsageError("cannot open an OpenGL 3.3 window: " + g_glfw_error);
    // The viewer's GL objects must go before the window's context does, also on exceptions.
    struct Window {
        GLFWwindow* window;
        std::unique_ptr<Viewer> viewer;
        ~Window() {
            viewer.reset();
            glfwDestroyWindow(window);
        }
    } w{window, nullptr};
    glfwMakeContextCurrent(window);
    glfwSwapInterval(1);

    w.viewer = std::make_unique<Viewer>(std::move(session), image_name, config);
    Viewer& viewer = *w.viewer;
    if (options.maximised) viewer.set_maximised(options.maximised);
    if (prepare) prepare(viewer);
    glfwSetWindowUserPointer(window, &viewer);
    glfwSetCursorPosCallback(window, on_cursor);
    glfwSetMouseButtonCallback(window, on_button);
    glfwSetScrollCallback(window, on_scroll);
    glfwSetKeyCallback(window, on_key);
    glfwSetCharCallback(window, on_char);
    glfwSetWindowRefreshCallback(window, on_refresh);

    std::optional<ScriptPlayer> player;
    if (options.script) player.emplace(*options.script);
    auto last = std::chrono::steady_clock::now();
    while (!viewer.quit_requested()) {
        const bool playing = player && !player->done();
        if (playing || viewer.needs_frame())
            glfwPollEvents();
        else  // sleep until input (or a background run's next hand-over): nothing else changes
            glfwWaitEventsTimeout(viewer.idle_wait_s());
        if (glfwWindowShouldClose(window)) {  // the close button: asks first when work is unsaved
            glfwSetWindowShouldClose(window, GLFW_FALSE);
            viewer.ask_quit("window closed");
            if (viewer.quit_requested()) break;
        }
        if (playing) {
            try {
                player->advance(viewer);
            } catch (const cli::UsageError& e) {
                fmt::print(stderr, "liveset: error: {}\n", e.what());
                player.reset();  // stop the script, keep the window
            }
        }
        if (!viewer.needs_frame() && !playing) continue;
        int fw = 1, fh = 1;
        glfwGetFramebufferSize(window, &fw, &fh);
        const auto now = std::chrono::steady_clock::now();
        const double dt = std::chrono::duration<double>(now - last).count();
        last = now;
        if (fw > 0 && fh > 0) {
            viewer.frame(0, fw, fh, dt);
            glfwSwapBuffers(window);
        }
    }
    glfwSetWindowUserPointer(window, nullptr);
    return 0;
}

}  // namespace liveset::viewer
