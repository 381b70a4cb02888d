// Viewer frame budget: the steps a frame takes, the upload of what they changed (fine and coarse
// surfaces), redraw pacing while work runs, and the 3D pane's level of detail (frame_budget.hpp).
#include <chrono>

#include "viewer.hpp"
#include "liveset/base/stopwatch.hpp"

namespace liveset::viewer {

namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

double Viewer::now_ms() const { return ms_since(epoch_); }

void Viewer::advance() {
    if (!session_) return;
    if (budget_.options().background) return run_in_background();
    const auto t0 = Clock::now();
    for (int n = 0; busy() && budget_.another_step(n, ms_since(t0)); ++n) {
        const auto s0 = Clock::now();
        if (segment_running_) segment_step();
        else swarm_step();
        budget_.record_step(ms_since(s0));
    }
}

void Viewer::reset_lod() {
    lod_.reset();
    view3d_coarse_ = false;
    if (!session_) return;
    const auto t0 = Clock::now();
    lod_ = std::make_unique<LodMesher>(session_->lattice(), session_->mesher().fragment_size(), budget_.options().lod_factor);
    lod_->rebuild(session_->field().phi());
    current_.mesh_ms += ms_since(t0);
    coarse_surface_.upload_all(lod_->mesher());
}

void Viewer::upload_fine() {
    const auto m0 = Clock::now();
    if (session_->flush_mesh() > 0.0) current_.mesh_ms += ms_since(m0);  // X a background run left unmeshed
    const std::vector<FragmentId> ids = session_->take_dirty_fragments();
    if (ids.empty()) return;
    const auto t0 = Clock::now();
    const render::UploadStats st = surface_.upload(session_->mesher(), ids);
    current_.uploaded += st.fragments;
    if (lod_) {  // the coarse level of detail follows the fine fragments
        const std::vector<FragmentId> coarse = lod_->update(session_->field().phi(), session_->mesher(), ids);
        if (!coarse.empty()) coarse_surface_.upload(lod_->mesher(), coarse);
    }
    const double ms = ms_since(t0);
    current_.upload_ms += ms;
    budget_.record_upload(ms);
}

void Viewer::upload() {
    if (!session_) return;
    if (background_active()) return handover();  // the worker's changes, at the hand-over pace
    upload_fine();
    if (refresh_coarse_preview(!busy() || budget_.redraw_due(now_ms()))) stale_ = true;
    if (session_->revision() != seen_revision_) {
        seen_revision_ = session_->revision();
        stale_ = true;
    }
    // While work runs, the panes showing it are redrawn at the pace the budget allows.
    if (stale_ && (!busy() || budget_.redraw_due(now_ms()))) {
        stale_ = false;
        mark_all_panes();
    }
    // Still again: the 3D pane goes back to full quality.
    if (view3d_coarse_ && !budget_.coarse(now_ms(), segment_running_ || drag_.active))
        pane_dirty_[static_cast<int>(Pane::kView3d)] = true;
}

void Viewer::render_3d(const render::Framebuffer& fb) {
    const auto t0 = Clock::now();
    render::SceneContent content = scene_content();
    const bool preview = preview_mesher_ != nullptr;
    view3d_coarse_ = !preview && lod_ && !capturing_ && budget_.coarse(now_ms(), segment_running_ || drag_.active);
    if (preview) {  // the coarse start's front: its point c lies at the image's index 2c + 0.5 (coarse_lattice)
        content.surface = preview_surface_.get();
        content.surface_scale = 2.0f;
        content.surface_offset = 0.5f;
    } else if (view3d_coarse_) {
        content.surface = &coarse_surface_;
        content.surface_scale = static_cast<float>(lod_->factor());  // LodMesher's index space
    }
    if (runner_) runner_->release();  // the draw reads only GPU buffers and copies: the worker may step meanwhile
    scene_renderer_->render(fb, camera_, content, scene_style);
    glFinish();  // llvmpipe draws at flush time: count the drawing in this frame
    const double ms = ms_since(t0);
    current_.draw_ms += ms;
    if (runner_) {  // the hand-over back: after the step the worker began meanwhile
        const auto w0 = Clock::now();
        runner_->acquire();
        current_.wait_ms += ms_since(w0);
    }
    // The coarse start's front, drawn at half the resolution: the image's grid's surface of that front
    // has about 2² times its triangles, so the frame after the switch knows to draw the level of
    // detail rather than meshing and drawing a whole fine surface at full quality first.
    if (!view3d_coarse_ && !capturing_) budget_.record_full_draw(preview ? 4.0 * ms : ms);
}

void Viewer::render_dirty_panes() {
    const auto t0 = Clock::now();
    bool drew = false;
    for (int i = 0; i < kPaneCount; ++i)
        if (pane_dirty_[i] || pane_buffers_[i].width() != pane_rects_[i].w || pane_buffers_[i].height() != pane_rects_[i].h) {
            render_pane(static_cast<Pane>(i));
            drew = true;
        }
    if (drew && busy()) budget_.record_redraw(now_ms(), ms_since(t0));
}

}  // namespace liveset::viewer
