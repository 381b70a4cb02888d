// The control panel (Dear ImGui) and the pane captions: image, tools, segmentation parameters and
// run/pause/step, swarm repair, undo/redo, saving, view, and the per-frame status.
#include <fmt/core.h>
#include <imgui.h>
#include <imgui_stdlib.h>

#include <cmath>
#include <string>
#include <string_view>
#include <utility>

#include "viewer.hpp"

namespace liveset::viewer {

void Viewer::help_marker(const char* text) {
    ImGui::SameLine();
    ImGui::TextDisabled("(?)");
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", text);
}

bool Viewer::panel_button(const char* label, const char* name) {
    const bool pressed = ImGui::Button(label);
    const ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
    button_rects_[name] = {static_cast<int>(lo.x), static_cast<int>(lo.y), static_cast<int>(hi.x - lo.x), static_cast<int>(hi.y - lo.y)};
    if (pressed) log_.add("button", {{"name", name}});
    return pressed;
}

void Viewer::draw_panel() {
    ImGui::SetNextWindowPos(ImVec2(static_cast<float>(panel_rect_.x), static_cast<float>(panel_rect_.y)));
    ImGui::SetNextWindowSize(ImVec2(static_cast<float>(panel_rect_.w), static_cast<float>(panel_rect_.h)));
    // The scroll bar always shown: text wrapped to the panel's width does not re-wrap (and move
    // every row below it) when the content grows past the window's height.
    ImGui::Begin("liveset", nullptr,
                 ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_AlwaysVerticalScrollbar);
    ImGui::PushItemWidth(150.0f);
    draw_image_section();
    ImGui::Separator();
    draw_tools_section();
    // The most used first, so a 720-pixel window shows them without scrolling (the panel scrolls).
    if (ImGui::CollapsingHeader("View", ImGuiTreeNodeFlags_DefaultOpen)) draw_view_section();
    if (session_ && ImGui::CollapsingHeader("Segmentation", ImGuiTreeNodeFlags_DefaultOpen)) draw_segmentation_section();
    if (session_ && ImGui::CollapsingHeader("Repair (agent swarm)", ImGuiTreeNodeFlags_DefaultOpen)) draw_repair_section();
    if (session_ && ImGui::CollapsingHeader("Holes (no ground truth)", ImGuiTreeNodeFlags_DefaultOpen)) draw_holes_section();
    if (session_ && ImGui::CollapsingHeader("Slice display", ImGuiTreeNodeFlags_DefaultOpen)) draw_display_section();
    if (ImGui::CollapsingHeader("Status", ImGuiTreeNodeFlags_DefaultOpen)) draw_status_section();
    if (session_ && ImGui::CollapsingHeader("History (Ctrl+Z, Ctrl+Y)")) draw_history_section();
    if (session_ && ImGui::CollapsingHeader("Seeds and workspace (Ctrl+S)")) draw_files_section();
    if (session_ && ImGui::CollapsingHeader("Save")) draw_save_section();
    if (!message_.empty()) {
        ImGui::Separator();
        ImGui::PushStyleColor(ImGuiCol_Text, message_is_error_ ? ImVec4(1.0f, 0.45f, 0.4f, 1.0f) : ImVec4(0.6f, 0.9f, 0.6f, 1.0f));
        ImGui::TextWrapped("%s", message_.c_str());
        ImGui::PopStyleColor();
    }
    ImGui::PopItemWidth();
    ImGui::End();
}

// The image: name, size, the intensity at the cursor, the cursor (1-based voxels, LPS and RAS mm, typed); a path to open another.
void Viewer::draw_image_section() {
    if (session_) {
        const Lattice& l = session_->lattice();
        ImGui::Text("%s", image_name_.c_str());
        ImGui::TextDisabled("%dx%dx%d, %.2gx%.2gx%.2g mm", l.dims().x, l.dims().y, l.dims().z, l.spacing().x, l.spacing().y, l.spacing().z);
        const float raw = session_->image()(cursor_), unit = session_->unit_image()(cursor_);
        ImGui::Text("intensity %.4g (normalised %.3f)  phi %.2f", raw, unit, session_->field().phi()(cursor_));
        draw_cursor_section();
    } else {
        ImGui::TextWrapped("No image. Give a path (NIfTI, MetaImage, NRRD, MINC, DICOM folder):");
    }
    ImGui::InputText("##open", &open_path_);
    ImGui::SameLine();
    if (!opening()) {
        if (panel_button("Open", "open")) open_image(open_path_);
        return;
    }
    if (panel_button("Cancel##open", "cancel_open")) cancel_open();
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - open_started_).count();
    ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "opening... %.1f s (reading, bias correction)", s);
}

// The mouse tools (crosshair, seed, target) and the seed radius.
void Viewer::draw_tools_section() {
    int tool = static_cast<int>(tool_);
    ImGui::RadioButton("Crosshair (1)", &tool, 0);
    ImGui::SameLine();
    ImGui::RadioButton("Seed (2)", &tool, 1);
    ImGui::SameLine();
    ImGui::RadioButton("Target (3)", &tool, 2);
    if (tool != static_cast<int>(tool_)) set_tool(static_cast<Tool>(tool));
    float radius = static_cast<float>(seed_radius);
    if (ImGui::SliderFloat("seed radius", &radius, 0.5f, 10.0f, "%.1f vox")) seed_radius = radius;
}

// µ, ε (or from the seeds), n, α; run, pause and step the segmentation.
void Viewer::draw_segmentation_section() {
    const SegmentStatus& st = session_->segment_status();
    if (st.coarse)  // the coarse start's run (SessionOptions::coarse_start): φ changes when it ends
        ImGui::Text("%zu seed(s), coarse start: %d iterations on 2x2x2 blocks", session_->seeds().size(), st.coarse_iterations);
    else if (st.coarse_iterations > 0)
        ImGui::Text("%zu seed(s), %d coarse + %d iterations%s", session_->seeds().size(), st.coarse_iterations, st.iterations,
                    st.converged ? ", converged" : "");
    else
        ImGui::Text("%zu seed(s), %d iterations%s", session_->seeds().size(), st.iterations, st.converged ? ", converged" : "");
    if (st.converged && !leak_warning_.empty()) {  // next to the run, not only in the status line at the panel's foot
        ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.45f, 0.4f, 1.0f));
        ImGui::TextWrapped("%s", leak_warning_.c_str());
        ImGui::PopStyleColor();
    }
    bool edited = false, done = false;
    ui_params_ = session_->params();  // edits apply at once: the session holds the truth
    ui_auto_window_ = session_->window_from_seeds();
    if (ImGui::Checkbox("mu, epsilon from the seeds (tissue model)", &ui_auto_window_)) edited = done = true;
    // µ and ε in the image's own units, typed (Enter or leaving the field applies); normalised after.
    const IntensityScale& sc = session_->scale();
    if (!ImGui::IsAnyItemActive()) ui_mu_raw_ = sc.to_raw(ui_params_.mu), ui_epsilon_raw_ = sc.raw_length(ui_params_.epsilon);
    // Typing a value takes the window off the seeds (the box unticks).
    ImGui::InputDouble("mu", &ui_mu_raw_, 0.0, 0.0, "%.5g");
    const ImVec2 mu_lo = ImGui::GetItemRectMin(), mu_hi = ImGui::GetItemRectMax();  // for a driving test
    button_rects_["mu_field"] = {static_cast<int>(mu_lo.x), static_cast<int>(mu_lo.y), static_cast<int>(mu_hi.x - mu_lo.x),
                                 static_cast<int>(mu_hi.y - mu_lo.y)};
    if (ImGui::IsItemDeactivatedAfterEdit())
        ui_params_.mu = (ui_mu_raw_ - sc.low) / (sc.high - sc.low), ui_auto_window_ = false, edited = done = true;
    ImGui::SameLine();
    ImGui::TextDisabled("%.3f", ui_params_.mu);
    ImGui::InputDouble("epsilon", &ui_epsilon_raw_, 0.0, 0.0, "%.5g");
    if (ImGui::IsItemDeactivatedAfterEdit()) ui_params_.epsilon = sc.unit_length(ui_epsilon_raw_), ui_auto_window_ = false, edited = done = true;
    ImGui::SameLine();
    ImGui::TextDisabled("%.3f", ui_params_.epsilon);
    help_marker("mu, epsilon in the image's units (grey: normalised to [0, 1]); the front grows where |I - mu| < epsilon");
    if (!params_note_.empty()) {  // where the values came from (the panel's font has no Greek)
        std::string note = params_note_;
        for (const auto& [greek, latin] : {std::pair{"µ", "mu"}, std::pair{"ε", "epsilon"}, std::pair{"α", "alpha"}})
            for (std::size_t at; (at = note.find(greek)) != std::string::npos;) note.replace(at, std::string_view(greek).size(), latin);
        ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
        ImGui::TextWrapped("%s", note.c_str());
        ImGui::PopStyleColor();
    }
    float n = static_cast<float>(ui_params_.n), alpha = static_cast<float>(ui_params_.alpha);
    if (ImGui::DragFloat("n", &n, 0.05f, 0.5f, 16.0f, "%.2f")) ui_params_.n = n, edited = true;
    done |= ImGui::IsItemDeactivatedAfterEdit();
    help_marker("steepness of the threshold speed at the window's edge (Eq. 3)");
    ui_auto_alpha_ = session_->alpha_automatic();
    if (ImGui::SliderFloat("alpha", &alpha, 0.0f, 0.95f, "%.2f")) {
        if (ui_auto_alpha_) ui_params_.smooth_mm = 0.0;  // a given α: no blur unless set, as `segment --alpha`
        ui_params_.alpha = alpha, ui_auto_alpha_ = false, edited = true;
    }
    done |= ImGui::IsItemDeactivatedAfterEdit();
    help_marker("curvature weight (Eq. 2; the curvature is per mm): smoother fronts that leak less");
    ImGui::SameLine();
    if (ImGui::Checkbox("auto##alpha", &ui_auto_alpha_)) edited = done = true;
    help_marker("alpha (and the smoothing) from the image's noise over the window's contrast and the voxel shape, as liveset segment chooses them");
    float smooth = static_cast<float>(ui_params_.smooth_mm);
    if (ImGui::SliderFloat("smooth mm", &smooth, 0.0f, 3.0f, "%.2f")) ui_params_.smooth_mm = smooth, ui_auto_alpha_ = false, edited = true;
    done |= ImGui::IsItemDeactivatedAfterEdit();
    help_marker("sigma of the Gaussian blur of the image the threshold term reads (automatic with alpha: half the finest voxel side on a noisy scan)");
    if (edited && apply_params(ui_params_, ui_auto_window_, ui_auto_alpha_)) {
        params_note_.clear();  // the user's own values from now on
        const ThresholdParams& p = session_->params();
        log_.add("params", {{"mu", p.mu}, {"epsilon", p.epsilon}, {"mu_raw", sc.to_raw(p.mu)}, {"epsilon_raw", sc.raw_length(p.epsilon)},
                            {"n", p.n}, {"alpha", p.alpha}, {"smooth_mm", p.smooth_mm}, {"auto_window", session_->window_from_seeds()},
                            {"auto_alpha", session_->alpha_automatic()}});
    }
    if (done) session_->end_action();
    if (panel_button(segment_running_ ? "Pause (Space)" : "Run (Space)", "run_segmentation")) set_segment_running(!segment_running_);
    ImGui::SameLine();
    if (panel_button("Step (S)", "step_segmentation")) {
        segment_step();
        session_->end_action();
    }
}

namespace {

// The swarm's rule (`liveset repair --decision`): fill (intensity), random, or cut a handle at the
// target (a brush of 3 voxels when none is set). The sheet rule needs a band: `liveset repair
// --find-holes` and the Find holes tool. Returns whether the choice changed.
bool draw_rule_combo(RepairOptions& o) {
    const EditDecision rules[] = {EditDecision::kIntensity, EditDecision::kRandom, EditDecision::kCut};
    const char* names[] = {"fill (intensity)", "random", "cut a handle"};
    int current = -1;
    for (int i = 0; i < 3; ++i)
        if (o.swarm.decision == rules[i]) current = i;
    if (current < 0) {
        ImGui::TextDisabled("rule: sheet (set by Find holes)");
        return false;
    }
    if (!ImGui::Combo("rule", &current, names, 3)) return false;
    o.swarm.decision = rules[current];
    if (o.swarm.decision == EditDecision::kCut && !(o.swarm.edit_range > 0)) o.swarm.edit_range = 3.0;
    return true;
}

}  // namespace

// The swarm: its target, agents, p, radius, rule; start, stop, step, clear.
void Viewer::draw_repair_section() {
    const auto& t = session_->target();
    if (t) ImGui::Text("target (%.1f, %.1f, %.1f), %zu agents", t->x, t->y, t->z, session_->agents().size());
    else ImGui::TextDisabled("no target: Target tool (3), click the surface");
    bool done = false;
    if (!ImGui::IsAnyItemActive()) ui_repair_ = session_->repair_options();  // applied when a slider is released
    int agents = static_cast<int>(ui_repair_.swarm.agents);
    if (ImGui::SliderInt("agents", &agents, 1, 2000)) ui_repair_.swarm.agents = static_cast<std::size_t>(agents);
    done |= ImGui::IsItemDeactivatedAfterEdit();
    float p = static_cast<float>(ui_repair_.swarm.act_probability), r = static_cast<float>(ui_repair_.swarm.edit_radius);
    if (ImGui::SliderFloat("p", &p, 0.0f, 1.0f, "%.2f")) ui_repair_.swarm.act_probability = p;
    done |= ImGui::IsItemDeactivatedAfterEdit();
    help_marker("probability that an agent edits the surface in a step");
    if (ImGui::SliderFloat("radius", &r, 0.5f, 8.0f, "%.1f vox")) ui_repair_.swarm.edit_radius = r;
    done |= ImGui::IsItemDeactivatedAfterEdit();
    help_marker("support of an agent's Gaussian edit");
    done |= draw_rule_combo(ui_repair_);
    if (ImGui::TreeNode("more")) {
        float range = static_cast<float>(ui_repair_.swarm.edit_range), expand = static_cast<float>(ui_repair_.swarm.expand_sigmas);
        if (ImGui::SliderFloat("edit range", &range, 0.0f, 40.0f, "%.1f vox")) ui_repair_.swarm.edit_range = range;
        done |= ImGui::IsItemDeactivatedAfterEdit();
        if (ImGui::SliderFloat("expand sigmas", &expand, 0.1f, 5.0f, "%.2f")) ui_repair_.swarm.expand_sigmas = expand;
        done |= ImGui::IsItemDeactivatedAfterEdit();
        if (budget_.options().background)
            ImGui::Text("steps: on a worker thread; the view follows every %.0f ms", budget_.options().handover_ms);
        else
            ImGui::Text("steps/frame: as fit in %.0f ms", budget_.options().frame_ms);
        ImGui::TreePop();
    }
    if (done) apply_repair_options(ui_repair_);
    if (panel_button(swarm_running_ ? "Stop swarm (T)" : "Start swarm (T)", "swarm")) set_swarm_running(!swarm_running_);
    ImGui::SameLine();
    if (panel_button("Step##swarm", "step_swarm")) {
        swarm_step();
        session_->end_action();
    }
    ImGui::SameLine();
    if (panel_button("Clear target", "clear_target")) clear_target();
}

// Frame rate and where the frame's time went.
void Viewer::draw_status_section() {
    const FrameStats& f = last_;
    if (fps_ > 0.0) ImGui::Text("%.1f FPS, frame %.1f ms (%s)", fps_, frame_ms_, renderer_.c_str());
    else ImGui::Text("idle, last frame %.1f ms (%s)", frame_ms_, renderer_.c_str());
    help_marker("over the last second: frames drawn per second, and their mean work (input to screen); the rest of the "
                "second is spent waiting, so FPS x frame <= 1 s. The viewer draws only when something changes.");
    ImGui::Text("last frame: level set %.2f  agents %.2f  mesh %.2f ms", f.level_set_ms, f.agents_ms, f.mesh_ms);
    ImGui::Text("upload %.2f  draw %.2f ms", f.upload_ms, f.draw_ms);
    ImGui::Text("fragments rebuilt %zu, uploaded %zu", f.fragments, f.uploaded);
    ImGui::Text("triangles %zu", surface_.triangle_count());
    if (f.segment_steps || f.swarm_steps) ImGui::TextDisabled("%d level-set / %d swarm steps this frame", f.segment_steps, f.swarm_steps);
}

// Undo and redo with what they would take back.
void Viewer::draw_history_section() {
    ImGui::BeginDisabled(!session_->can_undo());
    if (panel_button("Undo (Ctrl+Z)", "undo")) undo();
    ImGui::EndDisabled();
    ImGui::SameLine();
    ImGui::BeginDisabled(!session_->can_redo());
    if (panel_button("Redo (Ctrl+Y)", "redo")) redo();
    ImGui::EndDisabled();
    ImGui::TextDisabled("%zu to undo (%s), %zu to redo, %.1f MB", session_->undo_depth(), session_->next_undo_label().c_str(),
                        session_->redo_depth(), static_cast<double>(session_->history_bytes()) / 1e6);
}

// Save the mask, φ, the mesh or a screenshot.
void Viewer::draw_save_section() {
    ImGui::InputText("##mask", &mask_path_);
    ImGui::SameLine();
    if (panel_button("Save mask", "save_mask")) save_mask(mask_path_);
    ImGui::InputText("##phi", &phi_path_);
    ImGui::SameLine();
    if (panel_button("Save phi", "save_phi")) save_phi(phi_path_);
    ImGui::InputText("##mesh", &mesh_path_);
    ImGui::SameLine();
    if (panel_button("Save mesh", "save_mesh")) save_mesh(mesh_path_);
    ImGui::InputText("##shot", &screenshot_path_);
    ImGui::SameLine();
    if (panel_button("Screenshot", "screenshot")) save_screenshot(screenshot_path_, Pane::kView3d);
}

// Reset or maximise the 3D view; the six named views.
void Viewer::draw_view_section() {
    if (panel_button("Reset view (R)", "reset_view") && session_) {
        frame_3d();
        reset_slice_views();
    }
    ImGui::SameLine();
    bool max3d = maximised_ == Pane::kView3d;
    if (ImGui::Checkbox("3D only (F)", &max3d)) set_maximised(max3d ? std::optional<Pane>(Pane::kView3d) : std::nullopt);
    for (const char* name : {"superior", "anterior", "left", "right", "posterior", "inferior"}) {
        if (ImGui::SmallButton(name)) {
            render::CameraPose pose;
            render::OrbitCamera::named_pose(name, pose);
            camera_.set_pose(pose);
            camera_changed();
            log_.add("button", {{"name", std::string("view_") + name}});
        }
        if (std::string_view(name) != "right" && std::string_view(name) != "inferior") ImGui::SameLine();
    }
}

// A recovery file was found for the image: ask (modal) whether to restore it.
void Viewer::draw_recovery_offer() {
    if (!autosave_->offer_pending()) return;
    const char* title = "Restore unsaved work?";
    if (!ImGui::IsPopupOpen(title)) ImGui::OpenPopup(title);
    ImGui::SetNextWindowPos(ImVec2(static_cast<float>(window_width_) * 0.5f, static_cast<float>(window_height_) * 0.5f), ImGuiCond_Always,
                            ImVec2(0.5f, 0.5f));
    ImGui::SetNextWindowSize(ImVec2(480.0f, 0.0f));
    if (offer_frames_ < 3) redraw_frames_ = std::max(redraw_frames_, 2);  // until the dialog settles and is logged
    if (!ImGui::BeginPopupModal(title, nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize)) return;
    ImGui::TextWrapped("liveset found %s.", autosave_->offer_summary().c_str());
    ImGui::TextWrapped("Restore replaces the current surface with it; Discard deletes it.");
    bool done = false;
    const bool pressed_restore = panel_button("Restore", "restore");
    ImGui::SameLine();
    const bool pressed_discard = panel_button("Discard", "discard");
    // Tell a driving test where the buttons are once the dialog has its final size and place.
    if (++offer_frames_ == 3) {
        nlohmann::json rects = nlohmann::json::object();
        for (const char* name : {"restore", "discard"}) {
            const Rect& r = button_rects_[name];
            rects[name] = {r.x, r.y, r.w, r.h};
        }
        log_.add("recovery_offer", {{"file", autosave_->file().string()}, {"buttons", rects}});
    }
    if (pressed_restore) {
        if (autosave_->restore()) {
            show_session();
            saved_revision_ = ~std::uint64_t{0};  // the restored work is still unsaved
            log_.add("restore", {{"file", autosave_->file().string()}});
        }
        done = true;
    }
    if (pressed_discard) {
        autosave_->discard();
        done = true;
    }
    if (done) {
        report_autosave();
        mark_all_panes();
        // The dialog leaves the screen only in the next frames: draw them now, without waiting
        // for input (the window sleeps until an event otherwise).
        redraw_frames_ = std::max(redraw_frames_, 3);
        offer_closed_frames_ = 2;  // this frame still shows it; the next one is the first without
        ImGui::CloseCurrentPopup();
    }
    ImGui::EndPopup();
}

void Viewer::draw_pane_labels() {
    ImDrawList* draw = ImGui::GetBackgroundDrawList();
    for (int i = 0; i < kPaneCount; ++i) {
        const Rect& r = pane_rects_[i];
        if (r.w <= 0 || r.h <= 0) continue;
        const Pane pane = static_cast<Pane>(i);
        std::string text;
        if (pane == Pane::kView3d) {
            text = preview_mesher_ ? fmt::format("3D  coarse start's front: {} triangles on 2x2x2 blocks", coarse_preview_triangles())
                                   : fmt::format("3D  {} triangles", surface_.triangle_count());
        } else if (session_) {
            const render::SliceGeometry g = slice_viewport(pane, 1, 1).geometry;
            text = fmt::format("{}  slice {}/{}", pane == Pane::kAxial ? "Axial" : (pane == Pane::kSagittal ? "Sagittal" : "Coronal"),
                               g.slice_of(cursor_.cast<double>()) + 1, g.slices);
        }
        draw->AddText(ImVec2(static_cast<float>(r.x + 6), static_cast<float>(r.y + 4)), IM_COL32(230, 230, 230, 255), text.c_str());
        draw_edge_letters(pane, r);
        draw->AddRect(ImVec2(static_cast<float>(r.x), static_cast<float>(r.y)), ImVec2(static_cast<float>(r.x + r.w), static_cast<float>(r.y + r.h)),
                      IM_COL32(60, 60, 70, 255));
    }
}

}  // namespace liveset::viewer
