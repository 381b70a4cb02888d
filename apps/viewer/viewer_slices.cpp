// Slice panes: drawing (window/level texels, the overlay of label fill, ROI and speed preview, the
// contour, crosshair and seeds), zoom and pan (ITK-SNAP's mouse: right drag zooms about the press
// point, middle drag pans; Ctrl+wheel zooms about the pointer), window/level (Shift+left drag:
// right widens the window, up raises the level), the panel's cursor section (1-based voxels, LPS
// and RAS millimetres, typed entry of either) and display section, and the orientation letters.
#define GLFW_INCLUDE_NONE  // modifier codes only; epoxy declares OpenGL
#include <GLFW/glfw3.h>
#include <fmt/core.h>
#include <imgui.h>
#include <imgui_stdlib.h>

#include <cmath>

#include "viewer.hpp"

namespace liveset::viewer {

namespace {

constexpr render::SliceAxis kAxes[3] = {render::SliceAxis::kAxial, render::SliceAxis::kSagittal, render::SliceAxis::kCoronal};

nlohmann::json triple(Vec3d v) { return {v.x, v.y, v.z}; }
nlohmann::json triple(Vec3i v) { return {v.x, v.y, v.z}; }

}  // namespace

render::SliceViewport Viewer::slice_viewport(Pane pane, int width, int height) const {
    const int i = static_cast<int>(pane);
    render::SliceViewport vp = render::SliceViewport::fit(render::slice_geometry(session_->lattice(), kAxes[i]), width, height);
    const SlicePaneView& v = slices_.panes[static_cast<std::size_t>(i)];
    vp.zoom = v.zoom;
    if (v.centre_uv) vp.centre_uv = *v.centre_uv;
    return vp;
}

void Viewer::render_slice_pane(Pane pane, render::Framebuffer& fb, const Rect& r) {
    const int i = static_cast<int>(pane);
    const render::SliceViewport vp = slice_viewport(pane, r.w, r.h);
    const render::SliceGeometry& g = vp.geometry;
    const int slice = g.slice_of(cursor_.cast<double>());
    if (slice_shown_[i] != slice) {
        const std::vector<std::uint8_t> texels = render::window_texels(session_->image(), g, slice, slices_.window);
        slice_renderers_[i]->set_texels(g.width, g.height, texels);
        slice_shown_[i] = slice;
    }
    // While the coarse start runs, its front upsampled (the fine start but for what the image refuses) instead of φ, still the seeds.
    const std::vector<float> phi = preview_mesher_ ? render::upsampled_phi_slice(preview_phi_, g, slice)
                                                   : render::phi_slice(session_->field().phi(), g, slice);
    if (contour_slice_[i] != slice || contour_revision_[i] != session_->revision() || contour_preview_[i] != preview_generation_) {
        contours_[i] = render::zero_contour(phi, g);
        contour_slice_[i] = slice;
        contour_revision_[i] = session_->revision();
        contour_preview_[i] = preview_generation_;
    }
    const ThresholdParams params = session_->params();
    const std::vector<std::uint8_t> rgba = render::overlay_texels(g, slice, slices_.overlay, phi, session_->roi(),
                                                                  slices_.overlay.preview ? &session_->speed_image() : nullptr, &params);
    slice_renderers_[i]->set_overlay(g.width, g.height, rgba);
    render::SliceOverlay overlay;
    overlay.layer = true;
    if (slices_.contour) overlay.contour = contours_[i];
    overlay.cursor = g.to_uv(cursor_.cast<double>());
    const double texel_mm = std::min(g.u_mm, g.v_mm);
    for (const SeedBall& s : session_->seeds()) {
        const double d = std::abs(s.center[g.normal_axis] - slice);
        if (d <= s.radius) overlay.seeds.push_back({g.to_uv(s.center), std::sqrt(s.radius * s.radius - d * d) * texel_mm});
    }
    if (const auto& t = session_->target(); t && std::abs((*t)[g.normal_axis] - slice) <= 2.0) overlay.target = g.to_uv(*t);
    overlay.markers = hole_markers(g, slice);
    slice_renderers_[i]->render(fb, vp, overlay, render::SliceStyle{});
}

// --- zoom, pan, window/level -------------------------------------------------------------------

void Viewer::zoom_slice(Pane pane, double x, double y, double factor) {
    if (!session_ || pane == Pane::kView3d || !(factor > 0.0)) return;
    const int i = static_cast<int>(pane);
    const Rect r = pane_rects_[i];
    render::SliceViewport vp = slice_viewport(pane, r.w, r.h);
    factor = std::clamp(vp.zoom * factor, kMinSliceZoom, kMaxSliceZoom) / vp.zoom;
    vp = render::zoom_about(vp, {x - r.x, y - r.y}, factor);
    slices_.panes[static_cast<std::size_t>(i)] = {vp.zoom, vp.centre_uv};
    pane_dirty_[i] = true;
    request_redraw();
}

void Viewer::pan_slice(Pane pane, double dx, double dy) {
    if (!session_ || pane == Pane::kView3d) return;
    const int i = static_cast<int>(pane);
    const Rect r = pane_rects_[i];
    const render::SliceViewport vp = render::pan_by(slice_viewport(pane, r.w, r.h), {dx, dy});
    slices_.panes[static_cast<std::size_t>(i)] = {vp.zoom, vp.centre_uv};
    pane_dirty_[i] = true;
    request_redraw();
}

void Viewer::set_slice_view(Pane pane, double zoom, std::optional<Vec3d> centre) {
    if (!session_ || pane == Pane::kView3d) return;
    const int i = static_cast<int>(pane);
    SlicePaneView& v = slices_.panes[static_cast<std::size_t>(i)];
    v.zoom = std::clamp(zoom, kMinSliceZoom, kMaxSliceZoom);
    v.centre_uv.reset();
    if (centre) v.centre_uv = slice_viewport(pane, 1, 1).geometry.to_uv(*centre);
    pane_dirty_[i] = true;
    request_redraw();
    log_slice_view(pane, "set");
}

void Viewer::reset_slice_views() {
    slices_.panes = {};
    for (int i = 0; i < 3; ++i) pane_dirty_[i] = true;
    request_redraw();
}

void Viewer::log_slice_view(Pane pane, const char* gesture) {
    const SlicePaneView& v = slices_.panes[static_cast<std::size_t>(pane)];
    const Rect r = pane_rects_[static_cast<int>(pane)];
    const glm::dvec2 c = slice_viewport(pane, std::max(r.w, 1), std::max(r.h, 1)).centre_uv;
    log_.add("slice_view", {{"pane", pane_name(pane)}, {"gesture", gesture}, {"zoom", v.zoom}, {"centre_uv", {c.x, c.y}}});
}

bool Viewer::set_display_window(const render::DisplayWindow& window) {
    try {
        window.validate();
    } catch (const std::invalid_argument& e) {
        return fail(e.what());
    }
    slices_.window = window;
    slices_.window_preset.clear();
    slice_shown_ = {-1, -1, -1};
    mark_all_panes();
    log_.add("window", {{"low", window.low}, {"high", window.high}, {"level", window.level()}, {"width", window.width()}, {"preset", ""}});
    return true;
}

bool Viewer::set_window_preset(const std::string& preset) {
    if (!session_) return fail("open an image first");
    try {
        slices_.window = render::preset_window(preset, session_->image(), session_->roi());
    } catch (const std::invalid_argument& e) {
        return fail(e.what());
    }
    slices_.window_preset = preset;
    slice_shown_ = {-1, -1, -1};
    mark_all_panes();
    const render::DisplayWindow& w = slices_.window;
    log_.add("window", {{"low", w.low}, {"high", w.high}, {"level", w.level()}, {"width", w.width()}, {"preset", preset}});
    return true;
}

void Viewer::set_overlay_style(const render::OverlayStyle& style, bool contour) {
    slices_.overlay = style;
    slices_.overlay.label_opacity = std::clamp(style.label_opacity, 0.0f, 1.0f);
    slices_.contour = contour;
    mark_all_panes();
    log_.add("display", {{"label_opacity", slices_.overlay.label_opacity}, {"roi", render::to_string(style.roi)},
                         {"preview", style.preview}, {"contour", contour}});
}

bool Viewer::slice_drag(const Drag& d, double x, double y, double dx, double dy) {
    (void)x, (void)y;
    if (d.pane == Pane::kView3d) return false;
    if (d.button == 1) {  // ITK-SNAP: right drag zooms (up: in) about where the drag began
        zoom_slice(d.pane, d.start_x, d.start_y, std::pow(1.01, -dy));
        return true;
    }
    if (d.button == 2) {
        pan_slice(d.pane, dx, dy);
        return true;
    }
    if (d.button == 0 && (d.mods & GLFW_MOD_SHIFT)) {  // window/level
        const render::DisplayWindow w = slices_.window;
        const double width = w.width() * std::exp(0.005 * dx), level = w.level() - dy * w.width() / 300.0;
        slices_.window = render::DisplayWindow::from_level_width(level, width);
        slices_.window_preset.clear();
        slice_shown_ = {-1, -1, -1};
        mark_all_panes();
        return true;
    }
    return false;
}

void Viewer::slice_drag_end(const Drag& d) {
    if (d.pane == Pane::kView3d) return;
    if (d.button == 1 || d.button == 2) log_slice_view(d.pane, d.button == 1 ? "zoom" : "pan");
    if (d.button == 0 && (d.mods & GLFW_MOD_SHIFT)) set_display_window(slices_.window);
}

// The last item's rectangle for the event log's "ready" line (a driving test clicks there); a
// field's without its label.
void Viewer::remember_item(const char* name, bool field) {
    const ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
    const float w = field ? std::min(ImGui::CalcItemWidth(), hi.x - lo.x) : hi.x - lo.x;
    button_rects_[name] = {static_cast<int>(lo.x), static_cast<int>(lo.y), static_cast<int>(w), static_cast<int>(hi.y - lo.y)};
}

// --- cursor ------------------------------------------------------------------------------------

void Viewer::log_cursor(const char* how) {
    if (!session_) return;
    const Lattice& l = session_->lattice();
    log_.add("cursor", {{"how", how}, {"voxel", triple(cursor_)}, {"voxel1", triple(render::one_based(cursor_))},
                        {"lps", triple(render::lps_of(l, cursor_))}, {"ras", triple(render::ras_of(l, cursor_))}});
}

bool Viewer::set_cursor_from(Vec3d value, render::CursorUnits units) {
    if (!session_) return fail("open an image first");
    const auto v = render::voxel_from(session_->lattice(), value, units);
    if (!v) {
        const char* what = units == render::CursorUnits::kVoxel1 ? "voxel" : (units == render::CursorUnits::kLps ? "LPS point" : "RAS point");
        return fail(fmt::format("the {} ({:g}, {:g}, {:g}) lies outside the image", what, value.x, value.y, value.z));
    }
    set_cursor(*v);
    log_cursor("typed");
    return true;
}

// The cursor: 1-based voxel, LPS and RAS millimetres; Enter in a field moves the cursor there.
void Viewer::draw_cursor_section() {
    const Lattice& l = session_->lattice();
    const Vec3i v1 = render::one_based(cursor_);
    const Vec3d lps = render::lps_of(l, cursor_), ras = render::ras_of(l, cursor_);
    const auto field = [&](const char* label, const char* name, std::string& text, bool& editing) {
        const bool enter = ImGui::InputText(label, &text, ImGuiInputTextFlags_EnterReturnsTrue | ImGuiInputTextFlags_AutoSelectAll);
        remember_item(name, true);
        editing = ImGui::IsItemActive();
        return enter;
    };
    if (!slices_.voxel_editing) slices_.voxel_text = fmt::format("{} {} {}", v1.x, v1.y, v1.z);
    if (field("voxel (1-based)", "cursor_voxel", slices_.voxel_text, slices_.voxel_editing)) {
        if (const auto p = render::parse_triple(slices_.voxel_text)) set_cursor_from(*p, render::CursorUnits::kVoxel1);
        else fail("type three voxel numbers, 1-based as shown (e.g. 91 109 91)");
    }
    const Vec3d mm = slices_.mm_units == 0 ? lps : ras;
    if (!slices_.mm_editing) slices_.mm_text = fmt::format("{:.1f} {:.1f} {:.1f}", mm.x, mm.y, mm.z);
    if (field(slices_.mm_units == 0 ? "mm (LPS)" : "mm (RAS)", "cursor_mm", slices_.mm_text, slices_.mm_editing)) {
        if (const auto p = render::parse_triple(slices_.mm_text))
            set_cursor_from(*p, slices_.mm_units == 0 ? render::CursorUnits::kLps : render::CursorUnits::kRas);
        else fail("type three coordinates in millimetres (e.g. -12.5 30 40)");
    }
    ImGui::SameLine();
    if (ImGui::SmallButton(slices_.mm_units == 0 ? "use RAS" : "use LPS")) slices_.mm_units = 1 - slices_.mm_units;
    ImGui::TextDisabled("LPS %.1f %.1f %.1f  RAS %.1f %.1f %.1f", lps.x, lps.y, lps.z, ras.x, ras.y, ras.z);
}

// Window/level (presets, level and width typed), the label overlay's opacity, the contour, the
// ROI and the speed preview.
void Viewer::draw_display_section() {
    const auto remember = [&](const char* name, bool field = false) { remember_item(name, field); };
    ImGui::Text("window");
    for (const char* preset : render::kWindowPresets) {
        ImGui::SameLine();
        const bool on = slices_.window_preset == preset;
        if (on) ImGui::PushStyleColor(ImGuiCol_Button, ImGui::GetStyleColorVec4(ImGuiCol_ButtonActive));
        if (ImGui::SmallButton(preset)) set_window_preset(preset);
        if (on) ImGui::PopStyleColor();
        remember((std::string("window_") + preset).c_str());
    }
    float lw[2] = {static_cast<float>(slices_.window.level()), static_cast<float>(slices_.window.width())};
    if (ImGui::InputFloat2("level, width", lw, "%.4g", ImGuiInputTextFlags_EnterReturnsTrue)) {
        if (lw[1] > 0.0f) set_display_window(render::DisplayWindow::from_level_width(lw[0], lw[1]));
        else fail("the window's width must be positive");
    }
    remember("window_level_width", true);
    ImGui::TextDisabled("%.4g (black) to %.4g (white); Shift+drag", slices_.window.low, slices_.window.high);
    render::OverlayStyle style = slices_.overlay;
    bool contour = slices_.contour, changed = false;
    changed |= ImGui::SliderFloat("label opacity", &style.label_opacity, 0.0f, 1.0f, "%.2f");
    remember("label_opacity", true);
    changed |= ImGui::Checkbox("contour", &contour);
    ImGui::SameLine();
    changed |= ImGui::Checkbox("speed preview", &style.preview);
    remember("speed_preview");
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("blue where the threshold term D < 0: the front grows there (darker: faster)");
    if (session_->roi()) {
        int roi = static_cast<int>(style.roi);
        ImGui::Text("ROI");
        for (int k = 0; k < 3; ++k) {
            ImGui::SameLine();
            changed |= ImGui::RadioButton(render::to_string(static_cast<render::RoiStyle>(k)), &roi, k);
        }
        style.roi = static_cast<render::RoiStyle>(roi);
    }
    if (changed) set_overlay_style(style, contour);
}

// R/L, A/P, S/I at the middle of each slice pane's edges, from the image's direction cosines.
void Viewer::draw_edge_letters(Pane pane, const Rect& r) {
    if (!session_ || pane == Pane::kView3d) return;
    const render::SliceGeometry g = slice_viewport(pane, 1, 1).geometry;
    const render::EdgeLetters e = render::edge_letters(session_->lattice(), g);
    ImDrawList* draw = ImGui::GetBackgroundDrawList();
    const ImU32 colour = IM_COL32(255, 215, 90, 255);
    const float cx = static_cast<float>(r.x) + 0.5f * static_cast<float>(r.w), cy = static_cast<float>(r.y) + 0.5f * static_cast<float>(r.h);
    const auto put = [&](char c, float x, float y) {
        const char text[2] = {c, '\0'};
        for (const ImVec2 d : {ImVec2(-1, 0), ImVec2(1, 0), ImVec2(0, -1), ImVec2(0, 1)})  // dark rim: legible on white
            draw->AddText(ImVec2(x + d.x, y + d.y), IM_COL32(0, 0, 0, 255), text);
        draw->AddText(ImVec2(x, y), colour, text);
    };
    put(e.left, static_cast<float>(r.x) + 5.0f, cy - 7.0f);
    put(e.right, static_cast<float>(r.x + r.w) - 13.0f, cy - 7.0f);
    put(e.top, cx - 4.0f, static_cast<float>(r.y) + 4.0f);
    put(e.bottom, cx - 4.0f, static_cast<float>(r.y + r.h) - 18.0f);
}

}  // namespace liveset::viewer
