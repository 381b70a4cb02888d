// The paper's Figure 3 scenario: a box (50³ by default) centred in a lattice (100³) contracting
// under mean curvature flow F = κ until it vanishes or a step limit. Used by `liveset demo`, the
// benchmarks and the mesher's Figure 3 experiment (through the per-step hook).
#pragma once

#include <functional>
#include <vector>

#include "liveset/levelset/sparse_field.hpp"

namespace liveset {

struct BoxFlowOptions {
    int lattice = 100;      // lattice edge length (points)
    int box = 50;           // box edge length (points inside)
    int max_steps = 5000;   // step limit
    int layers = 2;         // sparse-field layers N
    float cfl = 0.5f;       // |Δφ| bound per step
};

struct FlowStepRecord {
    int step = 0;             // 1-based
    double time = 0.0;        // t after the step
    double dt = 0.0;
    std::size_t zero_layer = 0;  // zero-layer size after the step
    std::size_t band = 0;        // band size after the step
    std::size_t changed = 0;     // |X|
    double ms = 0.0;             // wall time of the step
};

struct BoxFlowReport {
    std::vector<FlowStepRecord> steps;
    bool vanished = false;   // the zero layer emptied before the step limit
    bool interrupted = false;
    double total_ms = 0.0;
    double median_step_ms() const;
};

// Hook called after every step with the field and the step's result; return false to stop.
using FlowHook = std::function<bool(const SparseField&, const StepResult&, const FlowStepRecord&)>;

// Builds the box level set (throws std::invalid_argument on bad options).
SparseField make_box_field(const BoxFlowOptions& options);

// Runs the flow on `field` (from make_box_field) until it vanishes, the step limit, or the hook says stop.
// `step` sets the CFL number and an optional time-step cap (the step mode is the caller's too).
BoxFlowReport run_curvature_flow(SparseField& field, int max_steps, const StepOptions& step, const FlowHook& hook = {});

}  // namespace liveset
