// `liveset view`: registers the subcommand on the CLI, loads the inputs (image, --mask / --phi,
// --roi, --seed), and runs the window, a headless script or the benchmark. Also the demo's live
// window (main.cpp hands open_demo_viewer to the demo command).
#pragma once

#include <CLI/CLI.hpp>

#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "liveset/session/session.hpp"

namespace liveset::viewer {
class Viewer;
}

namespace liveset::cli {

void add_view_command(CLI::App& app, const int& threads);

// True when a window can be opened here (DISPLAY or WAYLAND_DISPLAY is set).
bool viewer_display_available();

// Opens the viewer window on `session` (the demo, mid-repair); `prepare` runs once the viewer
// exists (set the target, start the swarm, ...). Returns the exit status.
int open_viewer_window(std::unique_ptr<Session> session, const std::string& title,
                       const std::function<void(viewer::Viewer&)>& prepare);

// The demo's window: the viewer on `session` with the swarm aimed at `target` and running (the
// phantom mid-repair). Returns the exit status when the user quits.
int open_demo_viewer(std::unique_ptr<Session> session, Vec3d target);

}  // namespace liveset::cli
