// Dear ImGui (1.86) for the viewer without a platform backend: the viewer feeds ImGui's input
// itself from its own event queue (identically in a GLFW window and headless, one button or key
// change per frame so quick clicks and key presses are never lost), and draws with the OpenGL 3 renderer backend.
#pragma once

#include "viewer.hpp"

namespace liveset::viewer {

class ImGuiBridge {
public:
    ImGuiBridge();  // context, style, key map (GLFW key codes), OpenGL 3 backend
    ~ImGuiBridge();
    ImGuiBridge(const ImGuiBridge&) = delete;
    ImGuiBridge& operator=(const ImGuiBridge&) = delete;

    void new_frame(int width, int height, double dt_seconds);
    void render();  // into the bound framebuffer

    // Applies one event to ImGui's input state (mouse position and buttons, wheel, keys, text).
    static void feed(const InputEvent& event);
    static bool wants_mouse();
    static bool wants_keyboard();
};

}  // namespace liveset::viewer
