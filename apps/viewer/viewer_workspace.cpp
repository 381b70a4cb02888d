// The viewer's files and lifecycle: seeds and workspaces saved and loaded from the panel, the
// "quit with unsaved work?" and "overwrite?" dialogs, the 3D view framed to the surface, and the
// frame timing shown in the status (FPS and frame time defined so that they agree).
#include <fmt/core.h>
#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <chrono>
#include <filesystem>

#include "liveset/render/camera_fit.hpp"
#include "seed_file.hpp"
#include "viewer.hpp"

namespace liveset::viewer {

namespace fs = std::filesystem;

bool Viewer::save_seeds(const std::string& path) {
    halt_run();
    if (!session_) return fail("open an image first");
    try {
        cli::write_seed_file(path, session_->seeds());
    } catch (const std::exception& e) {
        return fail(e.what());
    }
    message_ = fmt::format("saved {} seed(s) to {}", session_->seeds().size(), path);
    message_is_error_ = false;
    log_.add("save", {{"what", "seeds"}, {"path", path}, {"seeds", session_->seeds().size()}});
    return true;
}

bool Viewer::load_seeds(const std::string& path) {
    halt_run();
    if (!session_) return fail("open an image first");
    std::vector<SeedBall> seeds;
    try {
        seeds = cli::read_seed_file(path, seed_radius);
    } catch (const std::exception& e) {
        return fail(e.what());
    }
    std::size_t added = 0;
    std::string refused;
    for (const SeedBall& b : seeds) {
        try {
            if (!session_->lattice().contains(b.center)) throw std::invalid_argument("it lies outside the image");
            account(session_->add_seed(b));
            ++added;
        } catch (const std::invalid_argument& e) {
            if (refused.empty()) refused = fmt::format("; refused {}: {}", cli::format_seed(b), e.what());
        }
    }
    message_ = fmt::format("loaded {} of {} seed(s) from {}{}", added, seeds.size(), path, refused);
    message_is_error_ = added != seeds.size();
    log_.add("load", {{"what", "seeds"}, {"path", path}, {"added", added}, {"refused", seeds.size() - added}});
    return added == seeds.size();
}

bool Viewer::save_workspace(const std::string& path, bool overwrite) {
    halt_run();
    if (!session_) return fail("open an image first");
    std::error_code ec;
    const bool ours = std::find(own_files_.begin(), own_files_.end(), path) != own_files_.end();
    if (!overwrite && !ours && fs::exists(path, ec)) {
        overwrite_path_ = path;  // the panel asks
        redraw_frames_ = std::max(redraw_frames_, 2);
        log_.add("overwrite_prompt", {{"path", path}});
        return false;
    }
    session_->end_action();
    WorkspaceView view;
    view.camera = camera_.pose();
    view.cursor = cursor_;
    try {
        viewer::save_workspace(path, *session_, image_path_, config_.roi_path, config_.image_corrected, view);
    } catch (const std::exception& e) {
        return fail(e.what());
    }
    if (!ours) own_files_.push_back(path);
    message_ = "saved the workspace to " + path + " (+ " + workspace_state_path(path).filename().string() + ")";
    message_is_error_ = false;
    log_.add("save", {{"what", "workspace"}, {"path", path}, {"iterations", session_->marks().iterations}});
    autosave_->mark_saved();
    saved_revision_ = session_->revision();
    return true;
}

void Viewer::apply_workspace_view(const WorkspaceView& view) {
    camera_.set_pose(view.camera);
    fit_3d_pending_ = false;  // the user's own framing
    camera_changed();
    set_cursor(view.cursor);
}

// Seeds (the CLI's --seed format) and the workspace.
void Viewer::draw_files_section() {
    ImGui::InputText("##seeds", &seeds_path_);
    ImGui::SameLine();
    if (panel_button("Save seeds", "save_seeds")) save_seeds(seeds_path_);
    ImGui::SameLine();
    if (panel_button("Load", "load_seeds")) load_seeds(seeds_path_);
    ImGui::InputText("##workspace", &workspace_path_);
    ImGui::SameLine();
    if (panel_button("Save workspace", "save_workspace")) save_workspace(workspace_path_);
    help_marker("Ctrl+S saves the workspace; `liveset view --workspace FILE` continues it. Seeds: one I,J,K:R per line, "
                     "as `liveset segment --seed` (0-based voxels)");
}

void Viewer::ask_quit(const std::string& reason) {
    halt_run();
    if (quit_prompt_) {  // asked already: a second Ctrl+Q (or close) means it
        log_.add("quit_prompt", {{"answer", "quit"}, {"reason", reason}});
        request_quit(*quit_prompt_);
        return;
    }
    if (config_.headless || !unsaved()) {
        request_quit(reason);
        return;
    }
    quit_prompt_ = reason;
    redraw_frames_ = std::max(redraw_frames_, 3);
}

void Viewer::draw_quit_prompt() {
    if (!quit_prompt_) return;
    const char* title = "Quit with unsaved work?";
    if (!ImGui::IsPopupOpen(title)) ImGui::OpenPopup(title);
    ImGui::SetNextWindowPos(ImVec2(static_cast<float>(window_width_) * 0.5f, static_cast<float>(window_height_) * 0.5f), ImGuiCond_Always,
                            ImVec2(0.5f, 0.5f));
    ImGui::SetNextWindowSize(ImVec2(520.0f, 0.0f));
    if (!ImGui::BeginPopupModal(title, nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize)) return;
    const std::string kept = autosave_->enabled() && !autosave_->file().empty()
                                 ? "It is kept in the recovery file " + autosave_->file().string() +
                                       "; the next start on this image offers to restore it."
                                 : std::string("Autosave is off: it will be lost.");
    ImGui::TextWrapped("The segmentation has changes that are not saved (mask, phi or workspace). %s", kept.c_str());
    const bool quit = panel_button("Quit", "quit_confirm");
    ImGui::SameLine();
    const bool save = panel_button("Save workspace and quit", "quit_save");
    ImGui::SameLine();
    const bool cancel = panel_button("Cancel", "quit_cancel");
    const Rect& q = button_rects_["quit_confirm"];
    const Rect& c = button_rects_["quit_cancel"];
    if (q.w > 0 && !ImGui::IsWindowAppearing()) {  // laid out: tell a driving test where the buttons are (once)
        static constexpr const char* kLogged = "quit_prompt_logged";
        if (!button_rects_.count(kLogged)) {
            button_rects_[kLogged] = {};
            log_.add("quit_prompt", {{"file", autosave_->file().string()}, {"buttons", {{"quit", {q.x, q.y, q.w, q.h}}, {"cancel", {c.x, c.y, c.w, c.h}}}}});
        }
    }
    const bool saved = save && save_workspace(workspace_path_);
    if (save && !saved && !overwrite_path_.empty()) {  // the save asks first: that dialog instead of this one
        quit_prompt_.reset();
        button_rects_.erase("quit_prompt_logged");
        ImGui::CloseCurrentPopup();
    } else if (quit || saved) {
        log_.add("quit_prompt", {{"answer", save ? "save" : "quit"}});
        ImGui::CloseCurrentPopup();
        request_quit(*quit_prompt_);
    } else if (cancel) {
        log_.add("quit_prompt", {{"answer", "cancel"}});
        quit_prompt_.reset();
        button_rects_.erase("quit_prompt_logged");
        redraw_frames_ = std::max(redraw_frames_, 3);
        ImGui::CloseCurrentPopup();
    }
    ImGui::EndPopup();
}

void Viewer::draw_overwrite_prompt() {
    if (overwrite_path_.empty()) return;
    const char* title = "Overwrite the file?";
    if (!ImGui::IsPopupOpen(title)) ImGui::OpenPopup(title);
    ImGui::SetNextWindowPos(ImVec2(static_cast<float>(window_width_) * 0.5f, static_cast<float>(window_height_) * 0.5f), ImGuiCond_Always,
                            ImVec2(0.5f, 0.5f));
    ImGui::SetNextWindowSize(ImVec2(480.0f, 0.0f));
    if (!ImGui::BeginPopupModal(title, nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize)) return;
    ImGui::TextWrapped("%s exists and is not this session's workspace. Overwrite it?", overwrite_path_.c_str());
    const bool yes = panel_button("Overwrite", "overwrite_confirm");
    ImGui::SameLine();
    const bool no = panel_button("Cancel##overwrite", "overwrite_cancel");
    if (yes || no) {
        const std::string path = overwrite_path_;
        overwrite_path_.clear();
        redraw_frames_ = std::max(redraw_frames_, 3);
        ImGui::CloseCurrentPopup();
        if (yes) save_workspace(path, true);
    }
    ImGui::EndPopup();
}

void Viewer::frame_3d() {
    halt_run();
    if (!session_) return;
    const Rect r = pane_rects_[static_cast<int>(Pane::kView3d)];
    const double aspect = r.w > 0 && r.h > 0 ? static_cast<double>(r.w) / r.h : 1.0;
    render::CameraPose home = render::OrbitCamera::default_pose();
    camera_.frame(render::surface_bounds(session_->mesher()), home);
    home.zoom = render::zoom_to_fit(camera_, render::surface_box(session_->mesher()), aspect);
    camera_.frame(render::surface_bounds(session_->mesher()), home);
    camera_changed();
    const render::CameraPose& p = camera_.pose();
    log_.add("frame_3d", {{"zoom", p.zoom}, {"aspect", aspect}});
}

void Viewer::fit_3d_if_pending() {
    if (!fit_3d_pending_ || !session_) return;
    const Rect r = pane_rects_[static_cast<int>(Pane::kView3d)];
    if (r.w <= 0 || r.h <= 0) return;  // the 3D pane is hidden (another pane maximised)
    fit_3d_pending_ = false;
    frame_3d();
}

// Over the frames of the last second: FPS = their count / the time from the first one's start to
// the end of the last one; frame time = their mean work. So FPS × frame time ≤ 1 s (the rest is
// waiting for input or vsync). Fewer than two frames in the last second: FPS 0 (idle; the viewer
// draws only on change), frame time = the last frame's.
void Viewer::after_frame_timing(double wall_ms) {
    const double now = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
    frame_starts_.push_back(now - wall_ms / 1000.0);
    frame_work_ms_.push_back(wall_ms);
    while (frame_starts_.size() > 1 && frame_starts_.front() < now - 1.0) {
        frame_starts_.pop_front();
        frame_work_ms_.pop_front();
    }
    const double span = now - frame_starts_.front();
    if (frame_starts_.size() >= 2 && span > 0.0) {
        fps_ = static_cast<double>(frame_starts_.size()) / span;
        double sum = 0.0;
        for (double ms : frame_work_ms_) sum += ms;
        frame_ms_ = sum / static_cast<double>(frame_work_ms_.size());
    } else {
        fps_ = 0.0;
        frame_ms_ = wall_ms;
    }
}

}  // namespace liveset::viewer
