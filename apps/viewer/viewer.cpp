// Viewer core: frames (evolve -> upload U -> redraw dirty panes -> compose), layout, actions.
#include "viewer.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

#include "image_commands.hpp"
#include "imgui_bridge.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/render/png_writer.hpp"
#include "liveset/base/stopwatch.hpp"

namespace liveset::viewer {

namespace {

using Clock = std::chrono::steady_clock;

nlohmann::json to_json(Vec3d v) { return {v.x, v.y, v.z}; }

Vec3i rounded(Vec3d v) {
    return {static_cast<int>(std::lround(v.x)), static_cast<int>(std::lround(v.y)), static_cast<int>(std::lround(v.z))};
}

}  // namespace

Viewer::Viewer(std::unique_ptr<Session> session, std::string image_name, const ViewerConfig& config)
    : config_(config),
      session_(std::move(session)),
      image_name_(std::move(image_name)),
      image_path_(config.image_path),
      log_(config.log_events),
      autosave_(std::make_unique<Autosave>(config.autosave)),
      budget_(config.budget) {
    const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    renderer_ = renderer ? renderer : "unknown renderer";
    if (const auto cut = renderer_.find(" ("); cut != std::string::npos) renderer_.resize(cut);
    imgui_ = std::make_unique<ImGuiBridge>();
    scene_renderer_ = std::make_unique<render::SceneRenderer>();
    for (auto& r : slice_renderers_) r = std::make_unique<render::SliceRenderer>();
    params_note_ = config.params_note;
    if (!config.workspace_path.empty()) workspace_path_ = config.workspace_path;
    attach_session();
    if (config.workspace_view && session_) {
        apply_workspace_view(*config.workspace_view);
        own_files_.push_back(workspace_path_);
    }
    if (!config.open_warning.empty()) {
        message_ = config.open_warning;
        message_is_error_ = true;
        log_.add("warning", {{"message", config.open_warning}});
    }
}

Viewer::~Viewer() {
    cancel_open();
    if (open_job_.valid()) open_job_.wait();  // N4 stops at its next iteration; the result is dropped
    halt_run();
    autosave_->at_exit();
    report_autosave();
}

void Viewer::attach_session() {
    autosave_->attach(session_.get(), image_path_, config_.image_corrected);
    show_session();
    // What was loaded is on disk; restored unsaved work is not (it lives in the recovery file).
    saved_revision_ = session_ && !autosave_->restored() ? session_->revision() : ~std::uint64_t{0};
    report_autosave();
    if (autosave_->restored()) log_.add("restore", {{"file", autosave_->file().string()}});
    if (autosave_->offer_pending() && config_.headless)
        fmt::print(stderr, "liveset: note: found {}; --recover restores it\n", autosave_->offer_summary());
}

// Autosave's news goes to the status line, and to stderr when no one watches the window.
void Viewer::report_autosave() {
    bool routine = false;
    const std::string note = autosave_->take_message(&routine);
    if (note.empty()) return;
    if ((config_.headless || quit_) && !routine) fmt::print(stderr, "liveset: note: {}\n", note);
    message_ = note;
    message_is_error_ = false;
    redraw_frames_ = std::max(redraw_frames_, 1);
}

void Viewer::show_session() {
    slice_shown_ = {-1, -1, -1};
    contour_slice_ = {-1, -1, -1};
    segment_running_ = swarm_running_ = false;
    segment_end_reported_ = false;  // a new session: its convergence is checked afresh
    leak_warning_.clear();
    if (!session_) {
        mark_all_panes();
        return;
    }
    surface_.upload_all(session_->mesher());
    session_->take_dirty_fragments();
    reset_lod();
    camera_.frame(render::surface_bounds(session_->mesher()));
    fit_3d_pending_ = true;  // once the 3D pane has its size (frame_3d)
    const Vec3i d = session_->lattice().dims();
    cursor_ = {d.x / 2, d.y / 2, d.z / 2};
    reset_slice_views();
    set_window_preset("auto");
    ui_params_ = session_->params();
    ui_auto_window_ = session_->window_from_seeds();
    ui_auto_alpha_ = session_->alpha_automatic();
    ui_repair_ = session_->repair_options();
    seen_revision_ = session_->revision();
    holes_.reset();
    mark_all_panes();
}

void Viewer::request_quit(const std::string& reason) {
    if (quit_) return;
    halt_run();
    quit_ = true;
    autosave_->at_exit();
    report_autosave();
    nlohmann::json fields{{"reason", reason}, {"frames", frames_}, {"fps", fps_}, {"frame_ms", frame_ms_}};
    if (session_) {
        fields["seeds"] = session_->seeds().size();
        fields["undo_depth"] = session_->undo_depth();
        fields["iterations"] = session_->segment_status().iterations;
        fields["triangles"] = surface_.triangle_count();
        if (session_->target()) fields["target"] = to_json(*session_->target());
    }
    const render::CameraPose& p = camera_.pose();
    fields["camera"] = {{"yaw", p.yaw_deg}, {"pitch", p.pitch_deg}, {"zoom", p.zoom}};
    log_.add("exit", fields);
}

void Viewer::mark_all_panes() {
    pane_dirty_.fill(true);
    redraw_frames_ = std::max(redraw_frames_, 1);
}

void Viewer::camera_changed() {
    pane_dirty_[static_cast<int>(Pane::kView3d)] = true;
    redraw_frames_ = std::max(redraw_frames_, 1);
}

void Viewer::set_tool(Tool tool) {
    tool_ = tool;
    redraw_frames_ = std::max(redraw_frames_, 1);
}

void Viewer::set_cursor(Vec3i voxel) {
    if (!session_) return;
    const Vec3i d = session_->lattice().dims();
    voxel = {std::clamp(voxel.x, 0, d.x - 1), std::clamp(voxel.y, 0, d.y - 1), std::clamp(voxel.z, 0, d.z - 1)};
    if (voxel == cursor_) return;
    cursor_ = voxel;
    mark_all_panes();
}

void Viewer::set_maximised(std::optional<Pane> pane) {
    maximised_ = pane;
    if (window_width_ > 0) set_window_size(window_width_, window_height_);
    mark_all_panes();
}

void Viewer::set_window_size(int width, int height) {
    window_width_ = width;
    window_height_ = height;
    const int panel = std::min(config_.panel_width, width / 2);
    panel_rect_ = {0, 0, panel, height};
    const int x0 = panel, aw = std::max(width - panel, 2), h = std::max(height, 2);
    std::array<Rect, kPaneCount> r{};
    if (maximised_) {
        r[static_cast<int>(*maximised_)] = {x0, 0, aw, h};
    } else {
        const int w1 = aw / 2, h1 = h / 2;
        r[static_cast<int>(Pane::kAxial)] = {x0, 0, w1, h1};
        r[static_cast<int>(Pane::kSagittal)] = {x0 + w1, 0, aw - w1, h1};
        r[static_cast<int>(Pane::kCoronal)] = {x0, h1, w1, h - h1};
        r[static_cast<int>(Pane::kView3d)] = {x0 + w1, h1, aw - w1, h - h1};
    }
    for (int i = 0; i < kPaneCount; ++i)
        if (r[i].w != pane_rects_[i].w || r[i].h != pane_rects_[i].h) pane_dirty_[i] = true;
    pane_rects_ = r;
}

bool Viewer::needs_frame() const {
    if (background_active())  // no session reads
        return !events_.empty() || redraw_frames_ > 0 || drag_.active || handover_due() || holes_busy();  // an open: at hand-overs
    return !events_.empty() || redraw_frames_ > 0 || busy() || drag_.active || view3d_coarse_ || stale_ || holes_busy() || opening() ||
           (session_ && session_->revision() != seen_revision_);
}

void Viewer::push_event(const InputEvent& event) {
    events_.push_back(event);
    redraw_frames_ = std::max(redraw_frames_, 2);  // ImGui settles hover/active states in a frame or two
}

// ---------------------------------------------------------------------------------------------
// Frames

void Viewer::frame(GLuint target, int width, int height, double dt_seconds) {
    const auto t0 = Clock::now();
    begin_handover();  // a background run's worker waits between steps until end_handover()
    current_.wait_ms += ms_since(t0);
    set_window_size(width, height);
    fit_3d_if_pending();
    log_.set_frame(frames_);
    process_events();  // current_ already holds what scripts or the bench did since the last frame
    advance();
    poll_holes(true);
    poll_open(!background_active());  // a run's worker waits while a frame holds the hand-over
    autosave_->tick();
    report_autosave();
    upload();
    render_dirty_panes();
    compose(target, width, height);
    if (window_shot_pending_) {
        window_shot_pending_ = false;
        glBindFramebuffer(GL_READ_FRAMEBUFFER, target);
        if (target == 0) glReadBuffer(GL_BACK);
        try {
            render::write_png(screenshot_path_, render::read_bound_color(width, height));
            message_ = "saved the window to " + screenshot_path_;
            message_is_error_ = false;
            log_.add("screenshot", {{"path", screenshot_path_}, {"pane", "window"}});
        } catch (const std::exception& e) {
            fail(e.what());
        }
    }
    current_.triangles = surface_.triangle_count();
    last_ = current_;
    current_ = {};
    if (!ready_logged_ && !config_.headless) {  // the window is up and laid out: tell a driving test where things are
        ready_logged_ = true;
        nlohmann::json rects = nlohmann::json::object();
        for (const auto& [name, r] : button_rects_) rects[name] = {r.x, r.y, r.w, r.h};
        nlohmann::json panes = nlohmann::json::object();
        for (int i = 0; i < kPaneCount; ++i) {
            const Rect& r = pane_rects_[i];
            panes[pane_name(static_cast<Pane>(i))] = {r.x, r.y, r.w, r.h};
        }
        log_.add("ready", {{"width", width}, {"height", height}, {"buttons", rects}, {"panes", panes}});
    }
    if (offer_closed_frames_ > 0 && --offer_closed_frames_ == 0) log_.add("recovery_closed");  // drawn without the dialog
    after_frame_timing(ms_since(t0));
    (void)dt_seconds;
    ++frames_;
    if (redraw_frames_ > 0) --redraw_frames_;
    end_handover();
}

void Viewer::account(const SessionUpdate& u) {
    current_.level_set_ms += u.level_set_ms;
    current_.agents_ms += u.agents_ms;
    current_.mesh_ms += u.mesh_ms;
    current_.fragments += u.fragments.size();
}

void Viewer::segment_step() {
    if (!session_) return;
    halt_run();
    account(session_->segment_step());
    ++current_.segment_steps;
    check_segment_end();
}

void Viewer::check_segment_end() {
    const SegmentStatus& st = session_->segment_status();
    if (!st.converged && !st.vanished) {
        segment_end_reported_ = false;
        return;
    }
    const bool was_running = segment_running_;
    segment_running_ = false;
    session_->end_action();
    message_ = st.vanished                  ? "the front vanished"
               : st.coarse_iterations > 0 ? fmt::format("converged after {} iterations (and {} of the coarse start)", st.iterations, st.coarse_iterations)
                                          : fmt::format("converged after {} iterations", st.iterations);
    message_is_error_ = st.vanished;
    // Without a ROI on a head, as `segment`: a front that leaked out of the automatic brain mask
    // (checked once per convergence, reset by a non-converged step, a run's start or a new
    // session; steps taken after it keep the warning in the message).
    if (!segment_end_reported_) {
        leak_warning_ = st.converged ? cli::session_leak_warning(*session_, "--roi auto on the command line") : std::string();
        if (!leak_warning_.empty()) {
            log_.add("warning", {{"message", leak_warning_}});
            if (config_.headless) fmt::print(stderr, "liveset: warning: {}\n", leak_warning_);
        }
        segment_end_reported_ = true;
    }
    if (!leak_warning_.empty()) {
        message_ += ", but " + leak_warning_;
        message_is_error_ = true;
    }
    if (was_running) log_.add("segmentation", {{"running", false}, {"iterations", st.iterations}, {"converged", st.converged}});
}

void Viewer::swarm_step() {
    if (!session_) return;
    halt_run();
    if (!session_->target()) {
        swarm_running_ = false;
        fail("set a target first: click the surface with the target tool");
        return;
    }
    holes_.aimed_at(*session_->target());  // the next hole scan judges this site
    account(session_->swarm_step());
    ++current_.swarm_steps;
}

render::SceneContent Viewer::scene_content() {
    render::SceneContent c;
    std::vector<glm::vec3>& agents = agent_points_;
    c.lattice = &session_->lattice();
    c.surface = &surface_;
    agents.clear();
    for (const Agent& a : session_->agents())
        agents.emplace_back(static_cast<float>(a.position.x), static_cast<float>(a.position.y), static_cast<float>(a.position.z));
    c.agents = agents;
    if (session_->target()) {
        const Vec3d t = *session_->target();
        c.target = glm::vec3(static_cast<float>(t.x), static_cast<float>(t.y), static_cast<float>(t.z));
    }
    c.cursor = glm::vec3(static_cast<float>(cursor_.x), static_cast<float>(cursor_.y), static_cast<float>(cursor_.z));
    add_hole_markers(c);
    return c;
}

void Viewer::render_pane(Pane pane) {
    const int i = static_cast<int>(pane);
    const Rect r = pane_rects_[i];
    pane_dirty_[i] = false;
    if (r.w <= 0 || r.h <= 0) return;
    render::Framebuffer& fb = pane_buffers_[i];
    fb.resize(r.w, r.h);
    if (!session_) {
        fb.bind();
        glClearColor(0.05f, 0.05f, 0.06f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        return;
    }
    if (pane == Pane::kView3d) return render_3d(fb);
    render_slice_pane(pane, fb, r);
}

void Viewer::ensure_3d_rendered() {
    upload();
    const int i = static_cast<int>(Pane::kView3d);
    if (pane_dirty_[i] || pane_buffers_[i].width() != pane_rects_[i].w || pane_buffers_[i].height() != pane_rects_[i].h)
        render_pane(Pane::kView3d);
}

void Viewer::compose(GLuint target, int width, int height) {
    glBindFramebuffer(GL_FRAMEBUFFER, target);
    glViewport(0, 0, width, height);
    glDisable(GL_SCISSOR_TEST);
    glClearColor(0.06f, 0.06f, 0.07f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    for (int i = 0; i < kPaneCount; ++i) {
        const Rect& r = pane_rects_[i];
        if (r.w > 0 && r.h > 0 && pane_buffers_[i].valid()) pane_buffers_[i].blit_to(target, r.x, height - r.y - r.h);
    }
    imgui_->new_frame(width, height, 1.0 / 60.0);
    draw_panel();
    draw_pane_labels();
    if (!config_.headless) {
        draw_recovery_offer();
        draw_quit_prompt();
        draw_overwrite_prompt();
    }
    glBindFramebuffer(GL_FRAMEBUFFER, target);
    glViewport(0, 0, width, height);
    imgui_->render();
}

// ---------------------------------------------------------------------------------------------
// Actions

bool Viewer::fail(const std::string& what) {
    message_ = what;
    message_is_error_ = true;
    redraw_frames_ = std::max(redraw_frames_, 1);
    log_.add("error", {{"message", what}});
    return false;
}

bool Viewer::add_seed(Vec3d index, double radius) {
    if (!session_) return fail("open an image first");
    halt_run();
    try {
        account(session_->add_seed({index, radius}));
    } catch (const std::invalid_argument& e) {
        return fail(std::string(e.what()) + (config_.roi_by_default && session_->roi() ? cli::kDefaultRoiHint : ""));
    }
    message_ = fmt::format("seed {} at ({:.0f}, {:.0f}, {:.0f})", session_->seeds().size(), index.x, index.y, index.z);
    message_is_error_ = false;
    log_.add("seed", {{"index", to_json(index)}, {"radius", radius}, {"seeds", session_->seeds().size()}});
    return true;
}

bool Viewer::remove_seed_at(Vec3d index) {
    if (!session_) return fail("open an image first");
    halt_run();
    const auto k = session_->seed_at(index, 1.0);
    if (!k) return fail("no seed there");
    account(session_->remove_seed(*k));
    message_ = "seed removed";
    message_is_error_ = false;
    log_.add("remove_seed", {{"index", to_json(index)}, {"seeds", session_->seeds().size()}});
    return true;
}

void Viewer::set_segment_running(bool on) {
    if (!session_ || on == segment_running_) return;
    halt_run();
    if (on && !session_->has_surface()) {
        fail("place a seed first (seed tool: click in a slice)");
        return;
    }
    if (on) swarm_running_ = false;
    segment_running_ = on;
    if (on) segment_end_reported_ = false;  // a background run reports only its end: check that end afresh
    if (!on) session_->end_action();
    message_ = on ? "segmenting" : "segmentation paused";
    message_is_error_ = false;
    log_.add("segmentation", {{"running", on}, {"iterations", session_->segment_status().iterations}});
}

void Viewer::set_swarm_running(bool on) {
    if (!session_ || on == swarm_running_) return;
    halt_run();
    if (on && !session_->target()) {
        fail("set a target first: click the surface with the target tool");
        return;
    }
    if (on) segment_running_ = false;
    swarm_running_ = on;
    if (!on) session_->end_action();
    message_ = on ? "swarm repairing" : "swarm stopped";
    message_is_error_ = false;
    log_.add("swarm", {{"running", on}});
}

bool Viewer::set_target(Vec3d index) {
    if (!session_) return fail("open an image first");
    halt_run();
    try {
        session_->set_target(index);
    } catch (const std::invalid_argument& e) {
        return fail(e.what());
    }
    set_cursor(rounded(index));
    message_ = fmt::format("target ({:.1f}, {:.1f}, {:.1f})", index.x, index.y, index.z);
    message_is_error_ = false;
    log_.add("target", {{"index", to_json(index)}});
    return true;
}

void Viewer::clear_target() {
    if (!session_) return;
    halt_run();
    swarm_running_ = false;
    session_->clear_target();
    log_.add("clear_target");
}

std::optional<render::Pick> Viewer::click_3d(double x, double y, bool as_target) {
    if (!session_) return std::nullopt;
    halt_run();
    ensure_3d_rendered();
    const auto p = render::pick(pane_buffers_[static_cast<int>(Pane::kView3d)], static_cast<int>(std::floor(x)),
                                static_cast<int>(std::floor(y)), camera_, session_->lattice());
    if (!p) {
        fail("no surface under the pointer");
        return std::nullopt;
    }
    if (as_target && preview_mesher_) {  // the front drawn is the coarse start's; φ is still the seeds
        fail("the coarse start is still running: set a target once the surface has refined (Run on)");
        return std::nullopt;
    }
    Vec3d index{p->index.x, p->index.y, p->index.z};
    if (view3d_coarse_)  // the coarse surface lies within a voxel or two of the real one
        if (const auto q = session_->nearest_surface_point(index, 3.0)) index = *q;
    log_.add("pick", {{"pixel", {x, y}}, {"index", to_json(index)}, {"world", {p->world.x, p->world.y, p->world.z}}});
    if (as_target) {
        if (!set_target(index)) return std::nullopt;
    } else {
        set_cursor(rounded(index));
    }
    return p;
}

void Viewer::undo(int times) {
    if (!session_) return;
    halt_run();
    segment_running_ = swarm_running_ = false;
    for (int i = 0; i < times && session_->can_undo(); ++i) {
        const std::string label = session_->next_undo_label();
        account(session_->undo());
        message_ = "undid " + label;
        log_.add("undo", {{"action", label}, {"undo_depth", session_->undo_depth()}});
    }
    ui_params_ = session_->params();
    ui_auto_window_ = session_->window_from_seeds();
    ui_auto_alpha_ = session_->alpha_automatic();
    message_is_error_ = false;
}

void Viewer::redo(int times) {
    if (!session_) return;
    halt_run();
    segment_running_ = swarm_running_ = false;
    for (int i = 0; i < times && session_->can_redo(); ++i) {
        const std::string label = session_->next_redo_label();
        account(session_->redo());
        message_ = "redid " + label;
        log_.add("redo", {{"action", label}, {"redo_depth", session_->redo_depth()}});
    }
    ui_params_ = session_->params();
    ui_auto_window_ = session_->window_from_seeds();
    ui_auto_alpha_ = session_->alpha_automatic();
    message_is_error_ = false;
}

bool Viewer::apply_params(const ThresholdParams& params, bool window_from_seeds, bool alpha_automatic) {
    if (!session_) return fail("open an image first");
    halt_run();
    try {
        session_->set_params(params, window_from_seeds, alpha_automatic);
    } catch (const std::invalid_argument& e) {
        ui_params_ = session_->params();
        return fail(e.what());
    }
    ui_params_ = session_->params();
    ui_auto_window_ = session_->window_from_seeds();
    ui_auto_alpha_ = session_->alpha_automatic();
    return true;
}

bool Viewer::apply_repair_options(const RepairOptions& options) {
    if (!session_) return fail("open an image first");
    halt_run();
    try {
        session_->set_repair_options(options);
    } catch (const std::invalid_argument& e) {
        ui_repair_ = session_->repair_options();
        return fail(e.what());
    }
    ui_repair_ = session_->repair_options();
    return true;
}

}  // namespace liveset::viewer
