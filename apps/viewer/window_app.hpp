// The desktop window: GLFW 3.3 with an OpenGL 3.3 core context (through epoxy), window events
// turned into the viewer's input events, and a loop that sleeps until something happens (software
// rendering is slow: frames are drawn only when input arrives, the evolution runs or a script plays).
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "script.hpp"
#include "viewer.hpp"

namespace liveset::viewer {

struct WindowOptions {
    int width = 1280, height = 720;
    std::string title = "liveset";
    std::optional<Pane> maximised;
    const Script* script = nullptr;  // played one piece per frame, the window stays up afterwards
};

// True when a window can be opened (an X display is set).
bool display_available();

// Opens the window and runs until the user quits (Ctrl+Q or closing the window). Returns the exit
// status (0). Throws cli::UsageError when no window can be opened.
int run_window(std::unique_ptr<Session> session, const std::string& image_name, const ViewerConfig& config,
               const WindowOptions& options, const std::function<void(Viewer&)>& prepare = {});

}  // namespace liveset::viewer
