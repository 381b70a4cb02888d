// The repair loop: swarm move -> surface edits -> local level-set update -> incremental mesh.
#include "liveset/swarm/repair.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace liveset {

std::vector<RepairStepLog> run_repair(SparseField& field, const Grid<float>& image_unit, const Grid<std::uint8_t>* roi,
                                      std::span<const RepairTarget> targets, const RepairOptions& options,
                                      FragmentMesher* mesher, const std::atomic<bool>* interrupt) {
    validate(options.swarm);
    if (options.steps < 0) throw std::invalid_argument("the number of repair steps must not be negative");
    if (targets.empty()) throw std::invalid_argument("repair needs at least one target");
    if (!(image_unit.dims() == field.lattice().dims())) throw std::invalid_argument("image and level set differ in size");
    if (roi && !(roi->dims() == field.lattice().dims())) throw std::invalid_argument("region of interest and level set differ in size");
    std::vector<RepairTarget> order(targets.begin(), targets.end());
    for (const RepairTarget& t : order) {
        if (!field.lattice().contains(t.position)) throw std::invalid_argument("a repair target lies outside the image");
        if (t.step < 0) throw std::invalid_argument("a repair target's step must not be negative");
    }
    std::stable_sort(order.begin(), order.end(), [](const RepairTarget& a, const RepairTarget& b) { return a.step < b.step; });

    Swarm swarm(options.swarm);
    bool spawned = false;
    std::size_t next = 0;
    std::vector<RepairStepLog> log;
    using clock = std::chrono::steady_clock;
    for (int step = 0; step < options.steps; ++step) {
        if (interrupt && interrupt->load(std::memory_order_relaxed)) break;
        const auto t0 = clock::now();
        while (next < order.size() && order[next].step <= step) {
            if (!spawned) {
                swarm.spawn(field, order[next].position, options.spawn_radius);
                spawned = true;
            }
            swarm.set_target(order[next].position);
            ++next;
        }
        RepairStepLog rec;
        rec.step = step;
        if (spawned) {
            rec.on_surface = swarm.move(field).on_surface;
            std::vector<ZeroLayerEdit> edits = swarm.surface_edits(field, image_unit);
            if (roi) {
                // A lowered φ (growth) at a zero-layer point next to the ROI border could carry the
                // front out of the ROI: drop growth at points whose 6-neighbourhood leaves the ROI.
                const Lattice& l = field.lattice();
                std::erase_if(edits, [&](const ZeroLayerEdit& e) {
                    if (e.delta >= 0.0f) return false;
                    const Vec3i p = l.coord(e.point);
                    for (int k = 0; k < 7; ++k) {
                        Vec3i q = p;
                        if (k > 0) q[(k - 1) / 2] += (k % 2) ? 1 : -1;
                        if (!l.contains(q) || (*roi)(q) == 0) return true;
                    }
                    return false;
                });
            }
            rec.modified = edits.size();
            if (!edits.empty()) {
                const ChangedPoints x = field.apply_edits(edits, RepairScope::kLocal);
                rec.changed = x.size();
                if (mesher) rec.fragments = mesher->update(field.phi(), x.points).size();
            }
        }
        rec.ms = std::chrono::duration<double, std::milli>(clock::now() - t0).count();
        log.push_back(rec);
    }
    return log;
}

}  // namespace liveset
