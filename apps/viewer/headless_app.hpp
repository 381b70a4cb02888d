// Headless runs (`liveset view --headless`): an EGL surfaceless OpenGL context, the same viewer
// drawn into an offscreen framebuffer of the given size, driven by a script or the benchmark; no
// X server needed.
#pragma once

#include <memory>
#include <string>

#include "bench.hpp"
#include "script.hpp"
#include "viewer.hpp"

namespace liveset::viewer {

struct HeadlessOptions {
    int width = 1280, height = 720;
    std::optional<Pane> maximised;
    const Script* script = nullptr;
    std::optional<BenchOptions> bench;
};

// Returns the exit status; throws cli::UsageError on script failures and when no headless OpenGL
// context can be created.
int run_headless(std::unique_ptr<Session> session, const std::string& image_name, const ViewerConfig& config,
                 const HeadlessOptions& options);

}  // namespace liveset::viewer
