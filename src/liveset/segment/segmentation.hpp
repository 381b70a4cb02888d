// The segmentation loop: global sparse-field steps under a speed until the front stops moving,
// an iteration limit, or an interrupt (Ctrl-C in the CLI, the pause button in the viewer), with a
// progress hook that also receives each step's changed points X (for the incremental mesher).
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "liveset/grid/grid.hpp"
#include "liveset/levelset/sparse_field.hpp"
#include "liveset/segment/intensity.hpp"

namespace liveset {

struct SegmentationOptions {
    int max_iterations = 2000;
    // Converged when the number of inside points changed by less than
    // max(1, tolerance × zero-layer size) over the last `window` iterations (net: points flickering
    // across the front at the edge of the threshold window cancel out).
    int window = 20;
    double tolerance = 1e-3;
    // The step: the exact full-band step by default; `liveset segment` uses segment_step().
    StepOptions step;
};

// The sleeping window a segmentation uses when it lets converged stretches of front sleep: as many
// steps without a sign change nearby as the convergence window looks back over.
inline constexpr int kSegmentationSleepAfter = 20;

// The sleeping step: incremental, converged stretches of front sleeping after `sleep_after` steps
// without a sign change near them (docs/ARCHITECTURE.md, "Activity"; BrainWeb grey matter 4.5x
// faster than the exact step, Dice 0.9210 vs 0.9207).
inline StepOptions sleeping_step(int sleep_after = kSegmentationSleepAfter) {
    StepOptions o;
    o.mode = StepMode::kIncremental;
    o.sleep_after = sleep_after;
    return o;
}

// The step `liveset segment` and `view`, and Python's segment() and Session, take by default: the
// sleeping step with the thin-front rule (since session 72; docs/ARCHITECTURE.md, "Thin fronts").
inline StepOptions segment_step() {
    StepOptions o = sleeping_step();
    o.thin_fronts = true;
    return o;
}

// The name `liveset segment --step` gives a step (its report's "step", a workspace's): "sleeping"
// where converged stretches of front sleep, else "exact" (the full-band step's bits).
inline const char* step_name(const StepOptions& o) {
    return o.mode == StepMode::kIncremental && o.sleep_after > 0 ? "sleeping" : "exact";
}

// A step as the command line names it (`--step sleeping|exact`, `--thin-fronts` /
// `--no-thin-fronts`) and a recovery file records it; the default is segment_step()'s.
struct RecordedStep {
    bool sleeping = true;     // the sleeping step (incremental); false: the exact (full-band) one
    bool thin_fronts = true;  // the thin-front rule
    bool operator==(const RecordedStep&) const = default;
};
inline RecordedStep recorded_step(const StepOptions& o) { return {std::string_view(step_name(o)) == "sleeping", o.thin_fronts}; }
// The StepOptions the command line builds: sleeping_step() or the exact StepOptions{}, the rule as named.
inline StepOptions step_options(const RecordedStep& step) {
    StepOptions o = step.sleeping ? sleeping_step() : StepOptions{};
    o.thin_fronts = step.thin_fronts;
    return o;
}
// "--step sleeping --thin-fronts", "--step exact --no-thin-fronts", ...
inline std::string describe(const RecordedStep& step) {
    return std::string("--step ") + (step.sleeping ? "sleeping" : "exact") + (step.thin_fronts ? " --thin-fronts" : " --no-thin-fronts");
}

// Throws std::invalid_argument for non-positive limits, a negative/non-finite tolerance or bad step
// options.
void validate(const SegmentationOptions& options);

struct SegmentationProgress {
    int iteration = 0;          // 1-based
    std::size_t zero_layer = 0;  // after the step
    std::size_t awake = 0;       // zero-layer points the step evaluated (the rest slept)
    std::size_t band = 0;
    std::size_t changed = 0;     // |X|
    std::size_t flips = 0;       // points that changed side in this step
    std::size_t inside = 0;      // points inside after the step
    double dt = 0.0;
    double ms = 0.0;             // wall time of the step
    // 1: a step of the coarse start's half-resolution run (coarse_start.hpp), whose X and counts are
    // that grid's; 0: the image's own grid.
    int level = 0;
};

enum class StopReason { kConverged, kIterationLimit, kInterrupted, kVanished };
std::string to_string(StopReason reason);

struct SegmentationResult {
    int iterations = 0;
    StopReason reason = StopReason::kIterationLimit;
    double seconds = 0.0;
    std::size_t inside = 0;
};

// Convergence of a moving front as run_segmentation judges it (the viewer's session uses the same
// rule): the inside points are counted once, then kept up to date from each step's X; the front
// has converged when the net change of the inside count over the last `window` steps is below
// max(1, tolerance × zero-layer size) - points flickering across the front at the edge of the
// threshold window cancel out, a front still advancing does not.
class FrontConvergence {
public:
    // Validates `options` (std::invalid_argument) and counts the inside points of `phi`.
    FrontConvergence(const Grid<float>& phi, const SegmentationOptions& options);
    // After a step: the number of points that changed side. `candidates` must hold every point
    // whose side changed since the last call (a step's X, or just its sign changes when nothing
    // else changed the field in between); the others are checked and cost a read each.
    std::size_t record_step(const Grid<float>& phi, std::span<const PointIndex> candidates);
    std::size_t inside() const { return inside_count_; }
    // Adds the current inside count to the window; true when the front has converged.
    bool converged(std::size_t zero_layer);

private:
    // One byte per point, first touched by the constructor's pass on every thread (the grid's
    // allocator: left unset until written, huge-page blocks), not by a serial zero fill.
    std::vector<std::uint8_t, detail::GridAllocator<std::uint8_t>> inside_;
    std::size_t inside_count_ = 0;
    std::deque<std::size_t> recent_;
    int window_;
    double tolerance_;
};

// Called after every step with the progress and X; returning false interrupts the run. The hook
// must not change the field: the convergence test counts flips from each step's sign changes.
using SegmentationHook = std::function<bool(const SegmentationProgress&, const ChangedPoints&)>;

// A segmentation run its caller steps one iteration at a time (run_segmentation's loop; a session's
// coarse start, one iteration per Session::segment_step): the same steps, tests and reasons as
// run_segmentation, whoever calls. `field` and `speed` must outlive it; the field changes only
// through advance() while it runs.
class SegmentationRun {
public:
    // Validates `options` (std::invalid_argument) and counts the inside points of `field`.
    SegmentationRun(SparseField& field, const Speed& speed, const SegmentationOptions& options);
    // One iteration: the step, its progress (and X) to `hook` (false: the run is interrupted), the
    // convergence test and the iteration limit. A field without a zero layer ends the run before
    // stepping (kVanished). Returns true while the run goes on; a no-op once it ended.
    bool advance(const SegmentationHook& hook = {});
    // Ends the run as interrupted (the next advance() would have stepped).
    void interrupt();
    bool ended() const { return ended_; }
    // Iterations, reason (kIterationLimit until it ended otherwise) and the inside count; the
    // seconds are the caller's to time (0 here).
    const SegmentationResult& result() const { return result_; }

private:
    SparseField& field_;
    const Speed& speed_;
    SegmentationOptions options_;
    FrontConvergence convergence_;
    SegmentationResult result_;
    bool ended_ = false;
};

SegmentationResult run_segmentation(SparseField& field, const Speed& speed, const SegmentationOptions& options,
                                    const SegmentationHook& hook = {}, const std::atomic<bool>* interrupt = nullptr);

// Initialises `field` from seed balls (index space): φ is the signed distance to their union.
void init_from_seeds(SparseField& field, std::span<const SeedBall> seeds);
// The union of `field`'s inside with the seed balls (each re-initialised locally, as a seed the
// viewer adds: SparseField::unite_in_box).
void unite_seeds(SparseField& field, std::span<const SeedBall> seeds);

// φ < 0, intersected with the ROI when given (non-zero voxels), as a 0/1 mask.
Grid<std::uint8_t> inside_mask(const Grid<float>& phi, const Grid<std::uint8_t>* roi = nullptr);

}  // namespace liveset
