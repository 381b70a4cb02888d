// Mean curvature flow experiment (box in a lattice), timed step by step.
#include "liveset/levelset/curvature_flow.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>

#include "liveset/levelset/shapes.hpp"
#include "liveset/base/stopwatch.hpp"

namespace liveset {

double BoxFlowReport::median_step_ms() const {
    if (steps.empty()) return 0.0;
    std::vector<double> ms;
    ms.reserve(steps.size());
    for (const auto& s : steps) ms.push_back(s.ms);
    std::nth_element(ms.begin(), ms.begin() + static_cast<std::ptrdiff_t>(ms.size() / 2), ms.end());
    return ms[ms.size() / 2];
}

SparseField make_box_field(const BoxFlowOptions& o) {
    if (o.lattice < 4) throw std::invalid_argument("lattice size must be at least 4, got " + std::to_string(o.lattice));
    if (o.box < 1 || o.box > o.lattice - 2)
        throw std::invalid_argument("box size must be between 1 and lattice size - 2, got " + std::to_string(o.box));
    if (o.max_steps < 0) throw std::invalid_argument("step limit must not be negative");
    SparseField field(Lattice({o.lattice, o.lattice, o.lattice}), o.layers);
    const double c = (o.lattice - 1) / 2.0;
    const double h = o.box / 2.0;
    field.init_from_sdf(shapes::Box({c, c, c}, {h, h, h}));
    return field;
}

BoxFlowReport run_curvature_flow(SparseField& field, int max_steps, const StepOptions& options, const FlowHook& hook) {
    using clock = std::chrono::steady_clock;
    validate(options);
    const CurvatureSpeed speed(1.0f);
    BoxFlowReport report;
    double time = 0.0;
    const auto start = clock::now();
    for (int s = 1; s <= max_steps; ++s) {
        if (field.zero_layer().empty()) {
            report.vanished = true;
            break;
        }
        const auto t0 = clock::now();
        StepResult r = field.step(speed, options);
        const auto t1 = clock::now();
        time += r.dt;
        FlowStepRecord rec;
        rec.step = s;
        rec.time = time;
        rec.dt = r.dt;
        rec.zero_layer = field.zero_layer().size();
        rec.band = field.band_size();
        rec.changed = r.changed.size();
        rec.ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
        report.steps.push_back(rec);
        if (hook && !hook(field, r, rec)) {
            report.interrupted = true;
            break;
        }
    }
    if (!report.interrupted && field.zero_layer().empty()) report.vanished = true;
    report.total_ms = ms_since(start);
    return report;
}

}  // namespace liveset
