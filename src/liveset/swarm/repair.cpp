// The repair loop: swarm move -> surface edits -> topology guard (topology_guard.cpp) -> local level-set update.
#include "liveset/swarm/repair.hpp"
#include "liveset/base/stopwatch.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <ctime>
#include <stdexcept>

namespace liveset {

RepairLoop::RepairLoop(SparseField& field, const Grid<float>& image_unit, const Grid<std::uint8_t>* roi,
                       const RepairOptions& options)
    : field_(field), image_unit_(image_unit), roi_(roi), options_(options), swarm_(options.swarm) {
    validate(options);
    if (!(image_unit.dims() == field.lattice().dims())) throw std::invalid_argument("image and level set differ in size");
    if (roi && !(roi->dims() == field.lattice().dims())) throw std::invalid_argument("region of interest and level set differ in size");
}

void validate(const RepairOptions& options) {
    validate(options.swarm);
    if (options.steps < 0) throw std::invalid_argument("the number of repair steps must not be negative");
    if (!(options.respawn_distance >= 0)) throw std::invalid_argument("the respawn distance must be >= 0");
    if (!(options.spawn_radius > 0)) throw std::invalid_argument("the spawn radius must be > 0");
    if (options.swarm.decision == EditDecision::kCut && !options.topology_guard)
        throw std::invalid_argument("the cut decision needs the topology guard (it keeps only the flips that cut a handle)");
}

void RepairLoop::set_target(Vec3d target) {
    if (!field_.lattice().contains(target)) throw std::invalid_argument("a repair target lies outside the image");
    bool far = false;
    if (spawned_ && options_.respawn_distance > 0) {
        Vec3d centroid{0, 0, 0};
        for (const Agent& a : swarm_.agents()) centroid += a.position;
        centroid = centroid / static_cast<double>(swarm_.agents().size());
        far = norm(target - centroid) > options_.respawn_distance;
    }
    if (!spawned_ || far) {
        respawn(target);
        return;
    }
    swarm_.set_target(target);
}

void RepairLoop::respawn(Vec3d target) {
    if (!field_.lattice().contains(target)) throw std::invalid_argument("a repair target lies outside the image");
    swarm_.spawn(field_, target, options_.spawn_radius);
    swarm_.set_target(target);
    spawned_ = true;
}

RepairStep RepairLoop::step() {
    using clock = std::chrono::steady_clock;
    const auto t0 = clock::now();
    RepairStep out;
    out.log.step = steps_++;
    if (spawned_) {
        out.log.on_surface = swarm_.move(field_).on_surface;
        std::vector<ZeroLayerEdit> edits = swarm_.surface_edits(field_, image_unit_);
        if (roi_) {
            // A lowered φ (growth) at a zero-layer point next to the ROI border could carry the
            // front out of the ROI: drop growth at points whose 6-neighbourhood leaves the ROI.
            const Lattice& l = field_.lattice();
            std::erase_if(edits, [&](const ZeroLayerEdit& e) {
                if (e.delta >= 0.0f) return false;
                const Vec3i p = l.coord(e.point);
                for (int k = 0; k < 7; ++k) {
                    Vec3i q = p;
                    if (k > 0) q[(k - 1) / 2] += (k % 2) ? 1 : -1;
                    if (!l.contains(q) || (*roi_)(q) == 0) return true;
                }
                return false;
            });
        }
        if (options_.topology_guard) {
            GuardOptions go;
            go.pocket_limit = brush_pocket_limit(swarm_.options().edit_range);
            go.close_cracks = options_.close_cracks;
            go.roi = roi_;
            go.cut_handles = swarm_.options().decision == EditDecision::kCut;
            const auto g0 = clock::now();
            out.log.guarded = guard_topology(field_, edits, go);
            out.log.guard_ms = ms_since(g0);
        }
        out.log.modified = edits.size();
        if (!edits.empty()) {
            out.changed = field_.apply_edits(edits, RepairScope::kLocal);
            out.log.changed = out.changed.size();
            out.log.level_set_ms = field_.last_update_ms();
        }
    }
    out.log.ms = ms_since(t0);
    return out;
}

std::vector<RepairStepLog> run_repair(SparseField& field, const Grid<float>& image_unit, const Grid<std::uint8_t>* roi,
                                      std::span<const RepairTarget> targets, const RepairOptions& options,
                                      const std::atomic<bool>* interrupt) {
    validate(options);
    if (targets.empty()) throw std::invalid_argument("repair needs at least one target");
    std::vector<RepairTarget> order(targets.begin(), targets.end());
    for (const RepairTarget& t : order) {
        if (!field.lattice().contains(t.position)) throw std::invalid_argument("a repair target lies outside the image");
        if (t.step < 0) throw std::invalid_argument("a repair target's step must not be negative");
    }
    std::stable_sort(order.begin(), order.end(), [](const RepairTarget& a, const RepairTarget& b) { return a.step < b.step; });

    RepairLoop loop(field, image_unit, roi, options);
    std::size_t next = 0;
    std::vector<RepairStepLog> log;
    for (int step = 0; step < options.steps; ++step) {
        if (interrupt && interrupt->load(std::memory_order_relaxed)) break;
        const auto t0 = std::chrono::steady_clock::now();
        const std::clock_t c0 = std::clock();
        while (next < order.size() && order[next].step <= step) loop.set_target(order[next++].position);
        RepairStepLog rec = loop.step().log;
        rec.ms = ms_since(t0);
        rec.cpu_ms = 1000.0 * static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
        log.push_back(rec);
    }
    return log;
}

}  // namespace liveset
