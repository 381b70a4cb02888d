// The slice panes' display state kept by the viewer: each pane's zoom and pan, the display window
// (window/level) and its preset, the overlay style (label fill and opacity, ROI, speed preview),
// the zero contour on or off, and the panel's typed cursor fields.
#pragma once

#include <array>
#include <optional>
#include <string>

#include "liveset/render/slice_display.hpp"

namespace liveset::viewer {

struct SlicePaneView {
    double zoom = 1.0;                      // 1: the slice fits the pane
    std::optional<glm::dvec2> centre_uv;    // texel-space point at the pane's centre (nullopt: the slice's centre)
};

struct SliceDisplay {
    std::array<SlicePaneView, 3> panes;  // axial, sagittal, coronal (Pane order)
    render::DisplayWindow window;
    std::string window_preset = "auto";  // empty once dragged or typed
    render::OverlayStyle overlay;
    bool contour = true;
    // Panel fields: the cursor typed as 1-based voxels or millimetres.
    std::string voxel_text, mm_text;
    int mm_units = 0;  // 0 LPS, 1 RAS
    bool voxel_editing = false, mm_editing = false;  // the field is being typed in: not refreshed
};

inline constexpr double kMinSliceZoom = 0.25, kMaxSliceZoom = 64.0;

}  // namespace liveset::viewer
