// ImGui context, input feed and OpenGL 3 backend.
#include "imgui_bridge.hpp"

#define GLFW_INCLUDE_NONE  // key codes only; epoxy declares OpenGL
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <algorithm>

namespace liveset::viewer {

ImGuiBridge::ImGuiBridge() {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;  // never write imgui.ini into the working folder
    io.LogFilename = nullptr;
    io.BackendPlatformName = "liveset";
    io.KeyMap[ImGuiKey_Tab] = GLFW_KEY_TAB;
    io.KeyMap[ImGuiKey_LeftArrow] = GLFW_KEY_LEFT;
    io.KeyMap[ImGuiKey_RightArrow] = GLFW_KEY_RIGHT;
    io.KeyMap[ImGuiKey_UpArrow] = GLFW_KEY_UP;
    io.KeyMap[ImGuiKey_DownArrow] = GLFW_KEY_DOWN;
    io.KeyMap[ImGuiKey_PageUp] = GLFW_KEY_PAGE_UP;
    io.KeyMap[ImGuiKey_PageDown] = GLFW_KEY_PAGE_DOWN;
    io.KeyMap[ImGuiKey_Home] = GLFW_KEY_HOME;
    io.KeyMap[ImGuiKey_End] = GLFW_KEY_END;
    io.KeyMap[ImGuiKey_Insert] = GLFW_KEY_INSERT;
    io.KeyMap[ImGuiKey_Delete] = GLFW_KEY_DELETE;
    io.KeyMap[ImGuiKey_Backspace] = GLFW_KEY_BACKSPACE;
    io.KeyMap[ImGuiKey_Space] = GLFW_KEY_SPACE;
    io.KeyMap[ImGuiKey_Enter] = GLFW_KEY_ENTER;
    io.KeyMap[ImGuiKey_Escape] = GLFW_KEY_ESCAPE;
    io.KeyMap[ImGuiKey_KeyPadEnter] = GLFW_KEY_KP_ENTER;
    io.KeyMap[ImGuiKey_A] = GLFW_KEY_A;
    io.KeyMap[ImGuiKey_C] = GLFW_KEY_C;
    io.KeyMap[ImGuiKey_V] = GLFW_KEY_V;
    io.KeyMap[ImGuiKey_X] = GLFW_KEY_X;
    io.KeyMap[ImGuiKey_Y] = GLFW_KEY_Y;
    io.KeyMap[ImGuiKey_Z] = GLFW_KEY_Z;
    ImGui::StyleColorsDark();
    ImGuiStyle& style = ImGui::GetStyle();
    style.WindowRounding = 0.0f;
    style.FrameRounding = 2.0f;
    style.ItemSpacing.y = 3.0f;
    style.FramePadding.y = 2.0f;
    ImGui_ImplOpenGL3_Init("#version 330 core");
}

ImGuiBridge::~ImGuiBridge() {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui::DestroyContext();
}

void ImGuiBridge::new_frame(int width, int height, double dt_seconds) {
    ImGuiIO& io = ImGui::GetIO();
    io.DisplaySize = ImVec2(static_cast<float>(width), static_cast<float>(height));
    io.DisplayFramebufferScale = ImVec2(1.0f, 1.0f);
    io.DeltaTime = static_cast<float>(std::clamp(dt_seconds, 1e-4, 1.0));
    ImGui_ImplOpenGL3_NewFrame();
    ImGui::NewFrame();
}

void ImGuiBridge::render() {
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

void ImGuiBridge::feed(const InputEvent& e) {
    ImGuiIO& io = ImGui::GetIO();
    switch (e.type) {
        case InputEvent::Type::kMove:
            io.MousePos = ImVec2(static_cast<float>(e.x), static_cast<float>(e.y));
            break;
        case InputEvent::Type::kPress:
        case InputEvent::Type::kRelease:
            io.MousePos = ImVec2(static_cast<float>(e.x), static_cast<float>(e.y));
            if (e.button >= 0 && e.button < 5) io.MouseDown[e.button] = e.type == InputEvent::Type::kPress;
            break;
        case InputEvent::Type::kScroll:
            io.MouseWheel += static_cast<float>(e.scroll);
            break;
        case InputEvent::Type::kKey:
            if (e.key >= 0 && e.key < 512) io.KeysDown[e.key] = e.down;
            io.KeyCtrl = (e.mods & GLFW_MOD_CONTROL) != 0;
            io.KeyShift = (e.mods & GLFW_MOD_SHIFT) != 0;
            io.KeyAlt = (e.mods & GLFW_MOD_ALT) != 0;
            io.KeySuper = (e.mods & GLFW_MOD_SUPER) != 0;
            break;
        case InputEvent::Type::kChar:
            io.AddInputCharacter(e.codepoint);
            break;
    }
}

bool ImGuiBridge::wants_mouse() { return ImGui::GetIO().WantCaptureMouse; }
bool ImGuiBridge::wants_keyboard() { return ImGui::GetIO().WantCaptureKeyboard; }

}  // namespace liveset::viewer
