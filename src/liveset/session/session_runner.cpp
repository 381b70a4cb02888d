// SessionRunner: a worker steps the session; the controlling thread takes it at hand-over points.
#include "liveset/session/session_runner.hpp"

#include <chrono>
#include <stdexcept>

namespace liveset {

void SessionRunner::start(RunWork kind, int max_steps, StepHook hook) {
    if (held()) throw std::logic_error("SessionRunner::start while the caller holds the hand-over");
    stop();
    session_.set_deferred_meshing(true);
    stop_ = false;
    {
        std::lock_guard g(state_mutex_);
        state_ = {};
        state_.active = true;
        state_.status = session_.segment_status();
    }
    worker_ = std::thread([this, kind, max_steps, hook = std::move(hook)] { work(kind, max_steps, hook); });
}

// The worker: holds the mutex while it steps, parks between steps while the controller asks.
void SessionRunner::work(RunWork kind, int max_steps, StepHook hook) {
    std::unique_lock lock(mutex_);
    for (;;) {
        parked_.wait(lock, [&] { return requests_.load() == 0 || stop_.load(); });
        if (stop_) break;
        bool more = true;
        std::string error;
        RunState now;
        try {
            if (kind == RunWork::kSwarm && !session_.target()) throw std::invalid_argument("the swarm has no target");
            const SessionUpdate u = kind == RunWork::kSegment ? session_.segment_step() : session_.swarm_step();
            {
                std::lock_guard g(state_mutex_);
                ++state_.steps;
                state_.level_set_ms += u.level_set_ms;
                state_.agents_ms += u.agents_ms;
                state_.status = session_.segment_status();
                if (kind == RunWork::kSegment && (state_.status.converged || state_.status.vanished)) more = false;
                if (max_steps > 0 && state_.steps >= max_steps) more = false;
                now = state_;
            }
            if (more && hook && !hook(u, now)) more = false;
        } catch (const std::exception& e) {
            error = e.what();
            more = false;
        }
        if (!more) {
            std::lock_guard g(state_mutex_);
            state_.finished = true;
            state_.error = std::move(error);
            break;
        }
    }
    lock.unlock();
    finished_cv_.notify_all();
}

void SessionRunner::finish_join() {
    worker_.join();
    session_.set_deferred_meshing(false);  // meshes what is pending
    std::lock_guard g(state_mutex_);
    state_.active = false;
}

void SessionRunner::stop() {
    if (!worker_.joinable()) return;
    if (!held_.owns_lock()) {  // set the flag under the mutex: the parked worker cannot miss it
        ++requests_;
        held_.lock();
        --requests_;
    }
    stop_ = true;
    held_.unlock();
    parked_.notify_all();
    finish_join();
}

RunState SessionRunner::poll() {
    if (worker_.joinable() && state().finished) finish_join();  // the worker no longer needs the mutex
    return state();
}

RunState SessionRunner::state() const {
    std::lock_guard g(state_mutex_);
    return state_;
}

bool SessionRunner::wait_finished(double ms) const {
    std::unique_lock l(state_mutex_);
    return finished_cv_.wait_for(l, std::chrono::duration<double, std::milli>(ms), [&] { return !state_.active || state_.finished; });
}

void SessionRunner::acquire() {
    if (!worker_.joinable() || held_.owns_lock()) return;
    ++requests_;
    held_.lock();
    --requests_;
}

void SessionRunner::release() {
    if (!held_.owns_lock()) return;
    held_.unlock();
    parked_.notify_all();
}

}  // namespace liveset
