// A background run of a Session: a worker thread takes segmentation (or swarm) steps back to back
// - the same Session::segment_step() / swarm_step() calls, in the same order, as a caller stepping
// on its own thread, so φ is bit-identical whatever the timing - while the controlling thread
// (the viewer's render thread) keeps drawing and takes the accumulated changes at its own pace.
//
// Hand-over rule: the worker holds the runner's mutex while it steps and releases it between steps
// when the controlling thread asks (acquire(): the controller has priority, so it never waits more
// than one step). The controlling thread touches the Session only while it holds the hand-over
// (acquire() ... release()) or after stop() / a finished poll(); it reads state() at any time.
// While the run lasts the session defers its meshing (Session::set_deferred_meshing): the worker
// records X in the history, the controller meshes the union under the hand-over (flush_mesh /
// take_dirty_fragments). The steps stay one undoable action ("segment" or "repair") as when
// stepped in the foreground; stop() leaves it open for the caller to close (Session::end_action).
//
// start/stop/poll/acquire/release are for one controlling thread (not thread-safe among callers).
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include "liveset/session/session.hpp"

namespace liveset {

enum class RunWork { kSegment, kSwarm };

struct RunState {
    bool active = false;     // a worker exists (stepping, or finished and not yet joined)
    bool finished = false;   // the worker ended by itself: converged, vanished, step limit, hook, error
    int steps = 0;           // steps this run took
    double level_set_ms = 0.0, agents_ms = 0.0;  // summed over those steps (the worker's time)
    SegmentStatus status;    // the session's segment status after the last step
    std::string error;       // what a step threw (the run then finished)
};

class SessionRunner {
public:
    // After each step, on the worker and under the hand-over mutex: return false to end the run.
    using StepHook = std::function<bool(const SessionUpdate& update, const RunState& state)>;

    explicit SessionRunner(Session& session) : session_(session) {}
    ~SessionRunner() { stop(); }
    SessionRunner(const SessionRunner&) = delete;
    SessionRunner& operator=(const SessionRunner&) = delete;

    // Starts the worker (stopping a previous one first). A segmentation run ends by itself when
    // the front converges or vanishes; `max_steps` > 0 ends either kind after that many steps.
    // Throws std::logic_error while the caller holds the hand-over.
    void start(RunWork work, int max_steps = 0, StepHook hook = {});
    // Ends the run after the step in progress and joins the worker; no-op without one. Works also
    // while the caller holds the hand-over (it is released: the worker cannot step again after the
    // stop). The session's deferred meshing is turned off (pending X meshed); the action stays open.
    void stop();
    // The state now; a worker that finished by itself is joined (and meshing un-deferred) here.
    RunState poll();
    RunState state() const;
    bool active() const { return worker_.joinable(); }
    // Waits until the worker finished or `ms` passed; true when it finished (or there is none).
    bool wait_finished(double ms) const;

    // The hand-over: while held, the worker is parked between steps and the calling thread may
    // use the session. No-ops without a worker; acquire() while held, or release() while not, too.
    void acquire();
    void release();
    bool held() const { return held_.owns_lock(); }

private:
    void work(RunWork kind, int max_steps, StepHook hook);
    void finish_join();

    Session& session_;
    std::thread worker_;
    mutable std::mutex mutex_;                // the session's hand-over
    std::condition_variable parked_;          // the worker waits here while the controller asks
    std::atomic<int> requests_{0};            // the controller wants the mutex
    std::atomic<bool> stop_{false};
    std::unique_lock<std::mutex> held_{mutex_, std::defer_lock};  // the controller's hold
    mutable std::mutex state_mutex_;          // guards state_ (read at any time)
    mutable std::condition_variable finished_cv_;
    RunState state_;
};

}  // namespace liveset
