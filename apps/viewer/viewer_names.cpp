// Names of the viewer's panes and tools (scripts, the event log). Free of OpenGL, so the script
// parser can be fuzzed on its own.
#include "viewer.hpp"

namespace liveset::viewer {

const char* pane_name(Pane pane) {
    switch (pane) {
        case Pane::kAxial: return "axial";
        case Pane::kSagittal: return "sagittal";
        case Pane::kCoronal: return "coronal";
        case Pane::kView3d: return "3d";
    }
    return "?";
}

std::optional<Pane> pane_from_name(std::string_view name) {
    for (int i = 0; i < kPaneCount; ++i)
        if (name == pane_name(static_cast<Pane>(i))) return static_cast<Pane>(i);
    return std::nullopt;
}

const char* tool_name(Tool tool) {
    switch (tool) {
        case Tool::kCrosshair: return "crosshair";
        case Tool::kSeed: return "seed";
        case Tool::kTarget: return "target";
    }
    return "?";
}

}  // namespace liveset::viewer
