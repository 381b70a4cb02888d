// Viewer input: routing window events to the ImGui panel or to the panes, mouse gestures in the
// panes (ITK-SNAP conventions) and keyboard shortcuts.
//
// 3D pane: left drag rotates (Shift: pans), middle drag pans, right drag zooms, wheel zooms; a
// left click (no drag) picks the surface: it moves the crosshair there, and with the target tool
// aims the swarm there. Slice panes: wheel / Page Up / Page Down / arrow keys change the slice; a
// left click moves the crosshair (crosshair tool), places a seed (seed tool; right click removes
// the seed under the pointer) or aims the swarm at the surface point nearest the click (target);
// right drag zooms about the press point, middle drag pans, Ctrl+wheel zooms about the pointer,
// Shift+left drag sets window/level (viewer_slices.cpp); R resets the 3D view and the slices' zoom.
#define GLFW_INCLUDE_NONE  // key codes only; epoxy declares OpenGL
#include <GLFW/glfw3.h>
#include <fmt/core.h>

#include <cmath>

#include "imgui_bridge.hpp"
#include "viewer.hpp"

namespace liveset::viewer {

namespace {

constexpr double kClickTolerancePx = 3.0;

}  // namespace

std::optional<Pane> Viewer::pane_at(double x, double y) const {
    for (int i = 0; i < kPaneCount; ++i)
        if (pane_rects_[i].w > 0 && pane_rects_[i].contains(x, y)) return static_cast<Pane>(i);
    return std::nullopt;
}

std::optional<Vec3i> Viewer::voxel_at(Pane pane, double x, double y) const {
    if (!session_ || pane == Pane::kView3d) return std::nullopt;
    const Rect r = pane_rects_[static_cast<int>(pane)];
    const render::SliceViewport vp = slice_viewport(pane, r.w, r.h);
    const glm::dvec2 uv = vp.to_uv({x - r.x, y - r.y});
    const render::SliceGeometry& g = vp.geometry;
    if (uv.x < 0 || uv.y < 0 || uv.x >= g.width || uv.y >= g.height) return std::nullopt;
    const Vec3d p = g.to_index(uv, g.slice_of(cursor_.cast<double>()));
    return Vec3i{static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y)), static_cast<int>(std::lround(p.z))};
}

bool Viewer::routes_to_imgui(const InputEvent& e) const {
    switch (e.type) {
        case InputEvent::Type::kKey:
        case InputEvent::Type::kChar:
            return true;  // ImGui sees every key (text fields); shortcuts are decided separately
        case InputEvent::Type::kPress:
            return panel_rect_.contains(e.x, e.y) || ImGuiBridge::wants_mouse();
        case InputEvent::Type::kRelease:
            return !drag_.active;
        case InputEvent::Type::kScroll:
            return panel_rect_.contains(e.x, e.y);
        case InputEvent::Type::kMove:
            return !drag_.active;
    }
    return false;
}

void Viewer::process_events() {
    bool imgui_button_changed = false;
    while (!events_.empty()) {
        const InputEvent e = events_.front();
        const bool to_imgui = routes_to_imgui(e);
        const bool button = e.type == InputEvent::Type::kPress || e.type == InputEvent::Type::kRelease;
        if (to_imgui && (button || e.type == InputEvent::Type::kKey)) {
            // One button or key change per frame, so ImGui (1.86: state, not events) sees a quick
            // click's press and release, and a key pressed and released at once (Enter in a field).
            if (imgui_button_changed) break;
            imgui_button_changed = true;
        }
        events_.pop_front();
        if (e.type == InputEvent::Type::kMove || button) {
            mouse_x_ = e.x;
            mouse_y_ = e.y;
        }
        if (e.type == InputEvent::Type::kMove || to_imgui) ImGuiBridge::feed(e);
        if (e.type == InputEvent::Type::kKey) {
            // Ctrl+Q reaches the viewer also while the quit dialog holds the keyboard: twice quits.
            const bool quit_key = e.key == GLFW_KEY_Q && (e.mods & GLFW_MOD_CONTROL) && quit_prompt_;
            if (e.down && (!ImGuiBridge::wants_keyboard() || quit_key)) {
                budget_.record_input(now_ms());  // the 3D pane draws coarse until still again
                handle_key(e);
            }
        } else if (!to_imgui || (e.type == InputEvent::Type::kMove && drag_.active)) {
            handle_pane_event(e);
        }
    }
}

void Viewer::handle_pane_event(const InputEvent& e) {
    if (!session_) return;
    if (e.type != InputEvent::Type::kMove || drag_.active) budget_.record_input(now_ms());
    switch (e.type) {
        case InputEvent::Type::kPress: {
            const auto pane = pane_at(e.x, e.y);
            if (!pane) return;
            drag_ = {true, *pane, e.button, e.mods, e.x, e.y, e.x, e.y, false};
            return;
        }
        case InputEvent::Type::kMove: {
            if (!drag_.active) return;
            const double dx = e.x - drag_.last_x, dy = e.y - drag_.last_y;
            drag_.last_x = e.x;
            drag_.last_y = e.y;
            if (std::hypot(e.x - drag_.start_x, e.y - drag_.start_y) > kClickTolerancePx) drag_.moved = true;
            if (!drag_.moved) return;
            if (drag_.pane == Pane::kView3d) {
                const int h = pane_rects_[static_cast<int>(Pane::kView3d)].h;
                if ((drag_.button == 0 && (drag_.mods & GLFW_MOD_SHIFT)) || drag_.button == 2)
                    camera_.pan(dx, dy, h);
                else if (drag_.button == 0)
                    camera_.rotate(dx, dy);
                else if (drag_.button == 1)
                    camera_.zoom(std::pow(1.01, -dy));
                camera_changed();
            } else if (slice_drag(drag_, e.x, e.y, dx, dy)) {
            } else if (drag_.button == 0 && tool_ == Tool::kCrosshair) {
                if (const auto v = voxel_at(drag_.pane, e.x, e.y)) set_cursor(*v);  // ITK-SNAP: drag the crosshair
            }
            return;
        }
        case InputEvent::Type::kRelease: {
            if (!drag_.active) return;
            const Drag d = drag_;
            drag_.active = false;
            if (!d.moved) {
                pane_click(d.pane, e.x, e.y, d.button, d.mods);
            } else if (d.pane != Pane::kView3d) {
                slice_drag_end(d);
            } else {
                const render::CameraPose& p = camera_.pose();
                log_.add("camera", {{"gesture", d.button == 1 ? "zoom" : ((d.button == 2 || (d.mods & GLFW_MOD_SHIFT)) ? "pan" : "rotate")},
                                    {"yaw", p.yaw_deg}, {"pitch", p.pitch_deg}, {"zoom", p.zoom}});
            }
            return;
        }
        case InputEvent::Type::kScroll: {
            const auto pane = pane_at(e.x, e.y);
            if (!pane || e.scroll == 0.0) return;
            if (*pane == Pane::kView3d) {
                camera_.zoom(std::pow(1.1, e.scroll));
                camera_changed();
            } else if (e.mods & GLFW_MOD_CONTROL) {
                zoom_slice(*pane, e.x, e.y, std::pow(1.2, e.scroll));
                log_slice_view(*pane, "wheel");
            } else {
                const int axis = slice_viewport(*pane, 1, 1).geometry.normal_axis;
                Vec3i c = cursor_;
                c[axis] += e.scroll > 0 ? 1 : -1;
                set_cursor(c);
            }
            return;
        }
        default:
            return;
    }
}

void Viewer::pane_click(Pane pane, double x, double y, int button, int mods) {
    const Rect r = pane_rects_[static_cast<int>(pane)];
    if (pane == Pane::kView3d) {
        if (button != 0) return;
        click_3d(x - r.x, y - r.y, tool_ == Tool::kTarget || (mods & GLFW_MOD_CONTROL));
        return;
    }
    const auto v = voxel_at(pane, x, y);
    if (!v) return;
    const Vec3d p = v->cast<double>();
    switch (tool_) {
        case Tool::kCrosshair:
            if (button == 0 && !(mods & GLFW_MOD_SHIFT)) {
                set_cursor(*v);
                log_cursor("click");
            }
            break;
        case Tool::kSeed:
            if (button == 0) add_seed(p, seed_radius);
            else if (button == 1) remove_seed_at(p);
            break;
        case Tool::kTarget:
            if (button == 0) {
                if (const auto s = session_->nearest_surface_point(p, 10.0)) set_target(*s);
                else fail("no surface within 10 voxels of the click");
            }
            break;
    }
}

void Viewer::handle_key(const InputEvent& e) {
    const bool ctrl = (e.mods & GLFW_MOD_CONTROL) != 0, shift = (e.mods & GLFW_MOD_SHIFT) != 0;
    const auto hovered = pane_at(mouse_x_, mouse_y_);
    const auto slice_step = [&](int delta) {
        const Pane p = hovered && *hovered != Pane::kView3d ? *hovered : Pane::kAxial;
        if (!session_) return;
        const int axis = slice_viewport(p, 1, 1).geometry.normal_axis;
        Vec3i c = cursor_;
        c[axis] += delta;
        set_cursor(c);
    };
    const auto key_log = [&](const char* action) { log_.add("key", {{"key", e.key}, {"action", action}}); };
    if (ctrl && e.key == GLFW_KEY_Q) {
        key_log("quit");
        ask_quit("ctrl+q");
    } else if (ctrl && (e.key == GLFW_KEY_Y || (e.key == GLFW_KEY_Z && shift))) {
        key_log("redo");
        redo();
    } else if (ctrl && e.key == GLFW_KEY_S) {
        key_log("save workspace");
        save_workspace(workspace_path_);
    } else if (ctrl && e.key == GLFW_KEY_Z) {
        key_log("undo");
        undo();
    } else if (ctrl) {
        return;
    } else if (e.key == GLFW_KEY_SPACE) {
        key_log("run/pause segmentation");
        set_segment_running(!segment_running_);
    } else if (e.key == GLFW_KEY_S) {
        key_log("segmentation step");
        segment_step();
        if (session_) session_->end_action();
    } else if (e.key == GLFW_KEY_T) {
        key_log("start/stop swarm");
        set_swarm_running(!swarm_running_);
    } else if (e.key == GLFW_KEY_R) {
        key_log("reset view");
        frame_3d();  // the home direction, fitted to the surface
        reset_slice_views();
    } else if (e.key == GLFW_KEY_F12) {
        key_log("window screenshot");
        request_window_screenshot();
    } else if (e.key == GLFW_KEY_F) {
        key_log("maximise 3d");
        set_maximised(maximised_ ? std::nullopt : std::optional<Pane>(Pane::kView3d));
    } else if (e.key == GLFW_KEY_1 || e.key == GLFW_KEY_2 || e.key == GLFW_KEY_3) {
        const Tool t = e.key == GLFW_KEY_1 ? Tool::kCrosshair : (e.key == GLFW_KEY_2 ? Tool::kSeed : Tool::kTarget);
        set_tool(t);
        key_log(tool_name(t));
    } else if (e.key == GLFW_KEY_N || e.key == GLFW_KEY_P) {
        key_log(e.key == GLFW_KEY_N ? "next hole" : "previous hole");
        step_hole(e.key == GLFW_KEY_N ? 1 : -1);
    } else if (e.key == GLFW_KEY_PAGE_UP || e.key == GLFW_KEY_UP) {
        slice_step(1);
    } else if (e.key == GLFW_KEY_PAGE_DOWN || e.key == GLFW_KEY_DOWN) {
        slice_step(-1);
    }
}

}  // namespace liveset::viewer
