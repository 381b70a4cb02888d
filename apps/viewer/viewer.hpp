// The viewer's core, shared by the GLFW window, headless (EGL) runs, scripts and benchmarks: an
// ITK-SNAP-like layout (axial / sagittal / coronal / 3D panes and a control panel), the session it
// edits, one framebuffer per pane (a pane is redrawn only when what it shows changed), input
// routing (ImGui panel or panes), the actions the panel, the keyboard and the scripts share, and
// per-frame timing (level set, agents, meshing, upload, draw).
#pragma once

#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <deque>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "autosave.hpp"
#include "event_log.hpp"
#include "slice_panes.hpp"
#include "frame_budget.hpp"
#include "hole_tool.hpp"
#include "liveset/mesh/lod_mesher.hpp"
#include "liveset/render/framebuffer.hpp"
#include "liveset/render/orbit_camera.hpp"
#include "liveset/render/picking.hpp"
#include "liveset/render/scene_renderer.hpp"
#include "liveset/render/slice_renderer.hpp"
#include "liveset/render/surface_buffers.hpp"
#include "liveset/session/session.hpp"
#include "liveset/session/session_runner.hpp"
#include "workspace.hpp"

namespace liveset::viewer {

// ITK-SNAP's default arrangement: axial top-left, sagittal top-right, coronal bottom-left, 3D
// bottom-right.
enum class Pane { kAxial = 0, kSagittal = 1, kCoronal = 2, kView3d = 3 };
inline constexpr int kPaneCount = 4;
const char* pane_name(Pane pane);  // "axial", "sagittal", "coronal", "3d"
std::optional<Pane> pane_from_name(std::string_view name);

enum class Tool { kCrosshair, kSeed, kTarget };
const char* tool_name(Tool tool);

struct Rect {
    int x = 0, y = 0, w = 0, h = 0;  // window pixels, top-left origin
    bool contains(double px, double py) const { return px >= x && py >= y && px < x + w && py < y + h; }
};

// Window-system input, in window pixels (top-left origin); key codes and modifiers are GLFW's.
struct InputEvent {
    enum class Type { kMove, kPress, kRelease, kScroll, kKey, kChar };
    Type type = Type::kMove;
    double x = 0.0, y = 0.0;
    int button = 0;        // 0 left, 1 right, 2 middle
    double scroll = 0.0;   // wheel steps, positive away from the user
    int key = 0;
    int mods = 0;
    bool down = false;     // key pressed (or repeated) rather than released
    unsigned codepoint = 0;
};

// What one frame cost (milliseconds) and did.
struct FrameStats {
    double level_set_ms = 0.0, agents_ms = 0.0, mesh_ms = 0.0, upload_ms = 0.0, draw_ms = 0.0;
    double wait_ms = 0.0;            // waiting for a background run's hand-over (the worker's step in progress)
    std::size_t fragments = 0;       // rebuilt by the mesher this frame
    std::size_t uploaded = 0;        // fragment buffers re-uploaded this frame
    std::size_t triangles = 0;       // on the GPU after the frame
    int segment_steps = 0, swarm_steps = 0;
    double total_ms() const { return level_set_ms + agents_ms + mesh_ms + upload_ms + draw_ms; }
};

class ImGuiBridge;

struct ViewerConfig {
    bool headless = false;
    std::string log_events;  // JSON-lines event log (rewritten atomically at every event); empty: none
    int panel_width = 340;
    SessionOptions session;  // for images opened from the panel
    FrameBudgetOptions budget;  // steps per frame, redraw pacing and level of detail
    std::string image_path;  // the session's image as given (the key of its recovery file)
    AutosaveConfig autosave;  // recovery files (dir empty: none)
    std::string roi_path;     // the session's ROI as given, or as the default chose it: "auto" or "none" (saved in workspaces)
    bool roi_by_default = false;  // the automatic brain mask bounds the front by default (a seed outside: say --roi none)
    bool roi_none = false;        // --roi none on the command line: images opened from the panel get no ROI either
    // N4 first for images opened from the panel (as `view` and `segment` by default; skipped with a
    // message where it cannot run), and whether the session's image is N4-corrected (saved in
    // workspaces: a continued workspace corrects its image again, or not).
    bool bias_correct = true;
    bool image_corrected = false;
    // Whether the session's image file gave an orientation: saved masks and φ of one that gave none
    // are written without one too (WriteOptions).
    bool image_oriented = true;
    std::string params_note;  // where the start parameters came from (panel and stderr)
    std::string open_warning;  // what the start should warn about (the workspace's ROI changed): status line and event log
    std::string workspace_path;                   // the panel's workspace file (--workspace)
    std::optional<WorkspaceView> workspace_view;  // camera, cursor, ... of the workspace continued
};

class Viewer {
public:
    // Needs a current OpenGL 3.3 core context (window or headless). `session` may be null: the
    // panel then offers to open an image. `image_name` labels the window and the panel.
    Viewer(std::unique_ptr<Session> session, std::string image_name, const ViewerConfig& config);
    ~Viewer();
    Viewer(const Viewer&) = delete;
    Viewer& operator=(const Viewer&) = delete;

    // --- frames ---------------------------------------------------------------------------
    void push_event(const InputEvent& event);
    void request_redraw() { redraw_frames_ = std::max(redraw_frames_, 1); }
    // True while something is to be computed or shown (events queued, evolution running, a
    // redraw pending); the window sleeps otherwise.
    bool needs_frame() const;
    bool busy() const { return segment_running_ || swarm_running_; }
    // One frame into framebuffer `target` (0: the window) of width x height pixels: input,
    // evolution, upload of the rebuilt fragments, dirty panes, then panes + panel composed.
    void frame(GLuint target, int width, int height, double dt_seconds);
    const FrameStats& last_frame() const { return last_; }
    const FrameBudget& budget() const { return budget_; }
    bool view3d_coarse() const { return view3d_coarse_; }  // the 3D pane shows the coarse level of detail
    std::size_t coarse_triangles() const { return coarse_surface_.triangle_count(); }
    // The coarse start's preview (viewer_preview.cpp): while the session's coarse run is under way
    // the 3D pane draws its front (meshed on its grid of 2x2x2 blocks) and the slices fill and
    // outline its values upsampled onto the image's grid; from the frame after it ends, the surface.
    bool coarse_preview_shown() const { return preview_mesher_ != nullptr; }
    const FragmentMesher* coarse_preview_mesher() const { return preview_mesher_.get(); }
    std::size_t coarse_preview_triangles() const { return preview_surface_ ? preview_surface_->triangle_count() : 0; }
    // Over the frames of the last second: frames shown per second (0 when idle: the viewer draws
    // only on change) and their mean work in ms (input to composed panes); fps() * frame_ms() <= 1000.
    double fps() const { return fps_; }
    double frame_ms() const { return frame_ms_; }
    std::uint64_t frames() const { return frames_; }
    bool quit_requested() const { return quit_; }
    void request_quit(const std::string& reason);
    // Ctrl+Q and the window's close button: quits at once when nothing is unsaved (or headless),
    // else asks first (the dialog names the recovery file that keeps the work).
    void ask_quit(const std::string& reason);
    bool unsaved() const { return session_ && session_->revision() != saved_revision_; }

    // --- background run (viewer_background.cpp) --------------------------------------------
    // Running segmentation or swarm steps go to a worker thread (SessionRunner) unless the budget's
    // `background` is off; frames then hold its hand-over, and only frames touch the session.
    bool background_active() const { return runner_ && runner_->active(); }
    // Stops and joins the worker so the caller may use the session; segment_running() /
    // swarm_running() stay as they are (the next frame starts a worker again). Every action that
    // changes or reads the session outside a frame calls it first.
    void halt_run();
    // For loops without a window: sleeps until a frame is due (the next hand-over or the end of
    // the run), at most `max_ms`; returns at once without a background run.
    void wait_for_frame(double max_ms);
    // How long a window loop may sleep waiting for input (seconds).
    double idle_wait_s() const;

    // --- state ----------------------------------------------------------------------------
    Session* session() { return session_.get(); }
    const std::string& image_name() const { return image_name_; }
    Tool tool() const { return tool_; }
    void set_tool(Tool tool);
    Vec3i cursor() const { return cursor_; }
    void set_cursor(Vec3i voxel);
    render::OrbitCamera& camera() { return camera_; }
    void camera_changed();  // after changing camera() directly
    std::optional<Pane> maximised() const { return maximised_; }
    void set_maximised(std::optional<Pane> pane);
    void set_window_size(int width, int height);  // lays the panes out (frame() does it too)
    Rect pane_rect(Pane pane) const { return pane_rects_[static_cast<int>(pane)]; }
    Rect panel_rect() const { return panel_rect_; }
    const std::string& message() const { return message_; }
    EventLog& log() { return log_; }
    Autosave& autosave() { return *autosave_; }

    // --- actions: panel, keys and scripts share them; false + message() on failure ---------
    // Reads the image and prepares it (N4, as the command line does) on a worker thread, so the
    // window keeps drawing ("opening... s" and a Cancel button); a later frame swaps the new
    // session in (viewer_open.cpp). False (nothing started) while another image is opening.
    bool open_image(const std::string& path);
    bool opening() const { return open_job_.valid(); }
    // Drops the image being opened (N4 stops at its next iteration); the current session stays.
    void cancel_open();
    bool add_seed(Vec3d index, double radius);
    bool remove_seed_at(Vec3d index);
    void set_segment_running(bool on);
    bool segment_running() const { return segment_running_; }
    void segment_step();  // one step, accounted in this frame's statistics
    void set_swarm_running(bool on);
    bool swarm_running() const { return swarm_running_; }
    void swarm_step();
    bool set_target(Vec3d index);
    void clear_target();  // the swarm goes away
    // A click at pixel (x, y) of the 3D pane (pane coordinates): the surface point under it
    // (depth-buffer pick) becomes the cursor and, with `as_target`, the swarm's target.
    std::optional<render::Pick> click_3d(double x, double y, bool as_target);
    void undo(int times = 1);
    void redo(int times = 1);
    bool apply_params(const ThresholdParams& params, bool window_from_seeds, bool alpha_automatic);
    bool apply_repair_options(const RepairOptions& options);
    bool save_mask(const std::string& path);
    bool save_phi(const std::string& path);
    bool save_mesh(const std::string& path);
    // The workspace (workspace.hpp) of this session and view; an existing file this viewer did not
    // load or write is overwritten only with `overwrite` (the panel asks).
    bool save_workspace(const std::string& path, bool overwrite = false);
    bool save_seeds(const std::string& path);  // the --seed format, one per line
    bool load_seeds(const std::string& path);  // adds them (each refused outside the image or ROI)
    void frame_3d();  // fits the 3D view to the surface (key R)
    // Screenshot of a pane at its layout size (or width x height, supersampled) or of the whole
    // window (pane = nullopt) as the last frame laid it out.
    bool save_screenshot(const std::string& path, std::optional<Pane> pane, int width = 0, int height = 0, int supersample = 1);
    render::Image capture_pane(Pane pane, int width, int height, int supersample = 1);
    render::Image capture_window(int width, int height);
    // Saves exactly what the window shows (its back buffer after the next frame) to the panel's
    // screenshot path.
    void request_window_screenshot() { window_shot_pending_ = true; request_redraw(); }

    // --- slice panes (viewer_slices.cpp) ---------------------------------------------------
    const SliceDisplay& slice_display() const { return slices_; }
    // Zoom pane `pane` by `factor` about window pixel (x, y); pan it by (dx, dy) pixels.
    void zoom_slice(Pane pane, double x, double y, double factor);
    void pan_slice(Pane pane, double dx, double dy);
    void set_slice_view(Pane pane, double zoom, std::optional<Vec3d> centre);  // centre: a voxel
    void reset_slice_views();
    bool set_display_window(const render::DisplayWindow& window);  // a custom window
    bool set_window_preset(const std::string& preset);
    void set_overlay_style(const render::OverlayStyle& style, bool contour);
    // Moves the cursor to the voxel given as 1-based voxel numbers or millimetres (LPS, RAS).
    bool set_cursor_from(Vec3d value, render::CursorUnits units);

    // --- hole finder (viewer_holes.cpp; issue 18) --------------------------------------------
    // Starts the truth-free finder on the current segmentation (on a worker thread).
    bool find_holes(const HoleScanOptions& options);
    bool holes_busy() const { return holes_.running(); }
    // Takes an opened image, waiting up to a frame's pace for it with `wait`, and swaps the new
    // session in (or reports why it could not be opened; drops it when cancelled).
    void poll_open(bool wait);
    // Takes a finished scan (waiting a little with `wait`): the list, the markers, the verdicts.
    void poll_holes(bool wait);
    const HoleTool& hole_tool() const { return holes_; }
    // Candidate `rank` (1-based, largest first): the cursor moves to its site and the swarm is
    // aimed there (as a clicked target). step_hole: the next / previous one (keys N, P).
    bool select_hole(std::size_t rank);
    void step_hole(int delta);

    // Renders the 3D pane now if it is out of date (picking reads its depth buffer).
    void ensure_3d_rendered();

    // Seed radius used by clicks.
    double seed_radius = 2.0;
    render::SceneStyle scene_style;

private:
    struct Drag {
        bool active = false;
        Pane pane = Pane::kView3d;
        int button = 0;
        int mods = 0;
        double start_x = 0, start_y = 0, last_x = 0, last_y = 0;
        bool moved = false;
    };

    // viewer.cpp
    void attach_session();
    void show_session();  // renderer state for the session's current surface
    void report_autosave();
    void account(const SessionUpdate& update);
    void render_pane(Pane pane);
    void compose(GLuint target, int width, int height);
    void mark_all_panes();
    render::SliceViewport slice_viewport(Pane pane, int width, int height) const;
    render::SceneContent scene_content();
    bool fail(const std::string& what);
    // viewer_slices.cpp
    void render_slice_pane(Pane pane, render::Framebuffer& fb, const Rect& r);
    bool slice_drag(const Drag& d, double x, double y, double dx, double dy);  // true: handled
    void slice_drag_end(const Drag& d);
    void log_slice_view(Pane pane, const char* gesture);
    void log_cursor(const char* how);
    void draw_cursor_section();
    void draw_display_section();
    void draw_edge_letters(Pane pane, const Rect& r);
    void remember_item(const char* name, bool field);
    // viewer_budget.cpp
    double now_ms() const;  // since the viewer was made
    void advance();         // the steps that fit in this frame's budget
    void reset_lod();       // the coarse level of detail from scratch
    void upload();          // U (fine and coarse), then the panes due a redraw
    void upload_fine();     // the session's dirty fragments (meshed now if deferred), and the coarse ones they change
    void render_3d(const render::Framebuffer& fb);
    void render_dirty_panes();
    // viewer_preview.cpp: the coarse start's preview brought up to the session - dropped at once when
    // no coarse run is under way, begun at once, and updated from the points that changed when `due`
    // (the redraw pace) and the run took a step since; true when what it shows changed.
    bool refresh_coarse_preview(bool due);
    // viewer_input.cpp
    void process_events();
    bool routes_to_imgui(const InputEvent& e) const;
    void handle_pane_event(const InputEvent& e);
    void handle_key(const InputEvent& e);
    void pane_click(Pane pane, double x, double y, int button, int mods);
    std::optional<Pane> pane_at(double x, double y) const;
    std::optional<Vec3i> voxel_at(Pane pane, double x, double y) const;
    // viewer_panel.cpp
    void draw_panel();  // the sections below, in order
    void draw_image_section();
    void draw_tools_section();
    void draw_segmentation_section();
    void draw_repair_section();
    void draw_status_section();
    void draw_history_section();
    void draw_save_section();
    void draw_view_section();
    bool panel_button(const char* label, const char* name);
    static void help_marker(const char* text);  // a grey "(?)" with `text` as its tooltip
    void draw_pane_labels();
    void draw_recovery_offer();
    // viewer_holes.cpp
    void draw_holes_section();
    void draw_hole_list();
    std::vector<render::SliceMarker> hole_markers(const render::SliceGeometry& g, int slice) const;
    void add_hole_markers(render::SceneContent& c);
    // viewer_background.cpp
    void run_in_background();  // advance(): starts, polls and ends the worker
    void absorb_run(const RunState& state);  // the worker's steps into this frame's statistics
    bool handover_due() const;  // time for the render thread to take the run's changes
    void handover();            // upload() during a background run: the changes, when a redraw is due
    void begin_handover();      // frame(): hold the hand-over for the frame
    void end_handover();
    void check_segment_end();   // converged or vanished: the run stops (message, action closed)
    // viewer_workspace.cpp
    void draw_files_section();  // seeds and workspace: save / load
    void draw_quit_prompt();
    void draw_overwrite_prompt();
    void fit_3d_if_pending();
    void apply_workspace_view(const WorkspaceView& view);
    void after_frame_timing(double wall_ms);

    ViewerConfig config_;
    std::unique_ptr<Session> session_;
    std::unique_ptr<SessionRunner> runner_;  // a background run of session_ (after it: destroyed first)
    RunState run_seen_;                      // the worker's steps already accounted
    double last_handover_ms_ = -1e9;         // now_ms() of the last hand-over of a background run
    std::string image_name_;
    std::string image_path_;
    EventLog log_;
    std::unique_ptr<Autosave> autosave_;
    std::unique_ptr<ImGuiBridge> imgui_;
    std::unique_ptr<render::SceneRenderer> scene_renderer_;
    std::array<std::unique_ptr<render::SliceRenderer>, 3> slice_renderers_;
    std::array<int, 3> slice_shown_{-1, -1, -1};  // slice index in each slice renderer's texture
    render::SurfaceBuffers surface_;
    render::OrbitCamera camera_;
    std::array<render::Framebuffer, kPaneCount> pane_buffers_;
    std::array<bool, kPaneCount> pane_dirty_{true, true, true, true};
    std::array<Rect, kPaneCount> pane_rects_{};
    Rect panel_rect_;
    int window_width_ = 0, window_height_ = 0;
    std::optional<Pane> maximised_;
    std::uint64_t seen_revision_ = ~std::uint64_t{0};
    std::vector<glm::vec3> agent_points_;  // index space, refreshed per 3D draw
    std::array<std::vector<glm::dvec2>, 3> contours_;
    std::array<std::uint64_t, 3> contour_revision_{};
    std::array<int, 3> contour_slice_{-1, -1, -1};
    Tool tool_ = Tool::kCrosshair;
    Vec3i cursor_{};
    bool segment_running_ = false, swarm_running_ = false;
    std::deque<InputEvent> events_;
    double mouse_x_ = 0.0, mouse_y_ = 0.0;
    std::map<std::string, Rect> button_rects_;  // panel buttons, for the event log's "ready" line
    bool ready_logged_ = false;
    bool window_shot_pending_ = false;  // F12: save what the window shows after this frame
    int offer_frames_ = 0;              // frames the recovery dialog has been shown
    Drag drag_;
    FrameBudget budget_;
    std::chrono::steady_clock::time_point epoch_ = std::chrono::steady_clock::now();
    std::unique_ptr<LodMesher> lod_;
    render::SurfaceBuffers coarse_surface_;  // lod_'s fragments on the GPU
    bool view3d_coarse_ = false;             // the 3D pane was drawn from coarse_surface_
    std::unique_ptr<FragmentMesher> preview_mesher_;  // the coarse start's front (null: no coarse run under way)
    Grid<float> preview_phi_;                         // the coarse φ it meshed
    std::uint64_t preview_serial_ = 0;                // the session's coarse_serial() it shows
    std::uint64_t preview_generation_ = 0;            // bumped whenever what the preview shows changed
    std::array<std::uint64_t, 3> contour_preview_{};  // preview_generation_ of each slice's contour
    std::unique_ptr<render::SurfaceBuffers> preview_surface_;  // preview_mesher_'s fragments on the GPU (released with it)
    bool stale_ = false;                     // the session changed; panes not yet redrawn
    bool capturing_ = false;                 // capture_pane: the 3D pane at full quality
    int redraw_frames_ = 2;
    bool quit_ = false;
    std::string message_;
    std::string renderer_;  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
    bool message_is_error_ = false;
    bool segment_end_reported_ = false;  // the convergence's leak check done (check_segment_end)
    std::string leak_warning_;           // its warning, empty when none
    FrameStats current_, last_;
    double fps_ = 0.0, frame_ms_ = 0.0;
    std::deque<double> frame_starts_, frame_work_ms_;  // the frames of the last second: start (s), work (ms)
    std::uint64_t saved_revision_ = 0;  // the session's revision when its work was last on disk
    bool fit_3d_pending_ = true;        // frame the 3D view once the pane has its size
    std::optional<std::string> quit_prompt_;  // the quit request awaiting an answer
    std::string overwrite_path_;              // a workspace save awaiting "overwrite?"
    std::vector<std::string> own_files_;      // workspaces this viewer loaded or wrote
    int offer_closed_frames_ = 0;             // counts down to the first frame drawn without the recovery dialog
    std::string params_note_;
    std::uint64_t frames_ = 0;
    // Panel fields (kept between frames).
    std::string open_path_, mask_path_ = "segmentation.nii.gz", phi_path_ = "phi.nii.gz", mesh_path_ = "surface.ply",
                                screenshot_path_ = "screenshot.png";
    std::string workspace_path_ = "workspace.json", seeds_path_ = "seeds.txt";
    double ui_mu_raw_ = 0.0, ui_epsilon_raw_ = 0.0;
    ThresholdParams ui_params_;
    bool ui_auto_window_ = true;
    bool ui_auto_alpha_ = false;
    RepairOptions ui_repair_;
    SliceDisplay slices_;
    HoleTool holes_;                       // the hole finder's scan, list and selection
    struct Opened;                         // an image read and prepared by open_image's worker
    std::future<std::shared_ptr<Opened>> open_job_;
    std::shared_ptr<std::atomic<bool>> open_cancel_;  // the running open's interrupt (N4 polls it)
    std::string open_job_path_;
    std::chrono::steady_clock::time_point open_started_;
    HoleScanOptions ui_holes_;             // the panel's finder settings
    std::vector<glm::vec3> hole_points_;   // the 3D pane's markers, refreshed per draw
    std::string hole_rows_logged_;         // the list's rows as last logged for a driving test ("": not yet)
};

}  // namespace liveset::viewer
