// Viewer background runs: segmentation and swarm steps on a SessionRunner's worker thread while
// frames draw. Hand-over rule: a frame holds the runner's hand-over from its start to its end
// (released only around the 3D pane's GPU draw, which reads no session state), and the session is
// touched outside frames only after halt_run(); needs_frame() reads no session state meanwhile.
#include <fmt/core.h>

#include <algorithm>
#include <chrono>

#include "viewer.hpp"
#include "liveset/base/stopwatch.hpp"

namespace liveset::viewer {

using Clock = std::chrono::steady_clock;

void Viewer::begin_handover() {
    if (runner_) runner_->acquire();
}

void Viewer::end_handover() {
    if (runner_) runner_->release();
}

bool Viewer::handover_due() const {
    if (!background_active()) return true;
    return runner_->state().finished || now_ms() - last_handover_ms_ >= budget_.options().handover_ms;
}

void Viewer::absorb_run(const RunState& st) {
    current_.level_set_ms += st.level_set_ms - run_seen_.level_set_ms;
    current_.agents_ms += st.agents_ms - run_seen_.agents_ms;
    (segment_running_ ? current_.segment_steps : current_.swarm_steps) += st.steps - run_seen_.steps;
    run_seen_ = st;
}

void Viewer::halt_run() {
    if (!runner_) return;
    runner_->stop();  // joins the worker; its X is meshed (the upload takes the fragments)
    absorb_run(runner_->state());
    runner_.reset();
    run_seen_ = {};
}

// Called by advance() in a frame: the worker starts when a run is asked for, its progress is
// accounted, and a run that ended by itself is closed as a foreground run would be.
void Viewer::run_in_background() {
    if (!busy()) return halt_run();
    if (runner_) {
        const RunState st = runner_->poll();
        absorb_run(st);
        if (st.active) return;
        runner_.reset();
        run_seen_ = {};
        if (!st.error.empty()) {
            segment_running_ = swarm_running_ = false;
            session_->end_action();
            fail(st.error);
        } else if (segment_running_) {
            check_segment_end();
        }
        redraw_frames_ = std::max(redraw_frames_, 1);
        return;
    }
    if (swarm_running_ && !session_->target()) {
        swarm_running_ = false;
        fail("set a target first: click the surface with the target tool");
        return;
    }
    runner_ = std::make_unique<SessionRunner>(*session_);
    run_seen_ = {};
    runner_->start(segment_running_ ? RunWork::kSegment : RunWork::kSwarm);
    runner_->acquire();  // the rest of this frame holds the hand-over
    last_handover_ms_ = now_ms();
}

// The changes of a background run, at the redraw pace: while the 3D pane shows the coarse level of
// detail (a segmentation on software OpenGL), only the coarse surface follows φ - the fine mesh is
// built once, when the run stops; otherwise the fine fragments are meshed and uploaded as usual.
void Viewer::handover() {
    if (!handover_due()) return;
    last_handover_ms_ = now_ms();
    if (refresh_coarse_preview(budget_.redraw_due(now_ms()))) mark_all_panes();  // a coarse run moves no φ of the session's
    if (session_->revision() == seen_revision_ || !budget_.redraw_due(now_ms())) return;
    seen_revision_ = session_->revision();
    if (lod_ && budget_.coarse(now_ms(), segment_running_ || drag_.active)) {
        const auto t0 = Clock::now();
        const std::vector<FragmentId> coarse = lod_->refresh(session_->field().phi());
        const auto t1 = Clock::now();
        if (!coarse.empty()) coarse_surface_.upload(lod_->mesher(), coarse);
        current_.mesh_ms += std::chrono::duration<double, std::milli>(t1 - t0).count();
        current_.upload_ms += ms_since(t1);
    } else {
        upload_fine();
    }
    stale_ = false;
    mark_all_panes();
}

void Viewer::wait_for_frame(double max_ms) {
    if (!background_active() || !events_.empty()) return;
    const double left = budget_.options().handover_ms - (now_ms() - last_handover_ms_);
    if (left > 0.0) runner_->wait_finished(std::min(left, max_ms));
}

double Viewer::idle_wait_s() const {
    if (!background_active()) return 0.5;
    const double left = budget_.options().handover_ms - (now_ms() - last_handover_ms_);
    return std::clamp(left / 1000.0, 0.001, 0.5);
}

}  // namespace liveset::viewer
