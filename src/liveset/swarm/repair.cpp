// The repair loop: swarm move -> surface edits -> local level-set update -> incremental mesh.
#include "liveset/swarm/repair.hpp"

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdint>
#include <stdexcept>
#include <unordered_map>

#include "liveset/grid/digital_topology.hpp"

namespace liveset {

namespace {

constexpr std::size_t kPocketLimit = 32768;

// Visited marks for the pocket flood: one stamp per lattice point, reused across floods (a new
// stamp per flood, so nothing is cleared). Per thread: guard_topology may run on several threads.
struct FloodMarks {
    std::vector<std::uint32_t> stamp;
    std::uint32_t current = 0;
    std::vector<Vec3i> queue;
    void begin(std::size_t points) {
        if (stamp.size() != points || current == UINT32_MAX) {
            stamp.assign(points, 0);
            current = 0;
        }
        ++current;
        queue.clear();
    }
    bool visit(PointIndex i) {
        if (stamp[i] == current) return false;
        stamp[i] = current;
        return true;
    }
};

// Breadth-first flood of the outside (6-connected) from `start`: true when it ends within
// kPocketLimit voxels without reaching the lattice border. (A flat stamp array instead of a hash
// set: the flood is the guard's worst case, ~30 k voxels when the outside is large.)
template <class Inside>
bool encloses_small_pocket(const Lattice& lat, Inside& inside, Vec3i start) {
    thread_local FloodMarks marks;
    marks.begin(lat.size());
    std::vector<Vec3i>& queue = marks.queue;
    queue.push_back(start);
    marks.visit(lat.index(start));
    const Vec3i dims = lat.dims();
    for (std::size_t head = 0; head < queue.size(); ++head) {
        if (queue.size() > kPocketLimit) return false;
        const Vec3i p = queue[head];
        if (p.x == 0 || p.y == 0 || p.z == 0 || p.x == dims.x - 1 || p.y == dims.y - 1 || p.z == dims.z - 1) return false;
        for (int k = 0; k < 6; ++k) {
            Vec3i q = p;
            q[k / 2] += (k % 2) ? 1 : -1;
            if (inside(q) || !marks.visit(lat.index(q))) continue;
            queue.push_back(q);
        }
    }
    return true;
}

}  // namespace

std::size_t guard_topology(const SparseField& field, std::vector<ZeroLayerEdit>& edits) {
    const Lattice& lat = field.lattice();
    const Grid<float>& phi = field.phi();
    std::unordered_map<PointIndex, bool> flipped;  // accepted flips of this batch: point -> inside
    const auto inside = [&](Vec3i q) {
        if (!lat.contains(q)) return false;
        const PointIndex i = lat.index(q);
        if (const auto it = flipped.find(i); it != flipped.end()) return it->second;
        return phi[i] < 0.0f;
    };
    std::size_t dropped = 0;
    std::erase_if(edits, [&](const ZeroLayerEdit& e) {
        const float before = phi[e.point];
        const float after = before + std::clamp(e.delta, -0.5f, 0.5f);
        const bool was_in = before < 0.0f, is_in = after < 0.0f;
        if (was_in == is_in) return false;
        const Vec3i c = lat.coord(e.point);
        const TopologicalNumbers t = topological_numbers(inside, c);
        bool ok = is_in ? t.foreground == 1 : (t.background == 1 && t.foreground <= 1);
        // Growth that splits the local background either closes a tunnel (good) or seals a small
        // pocket off (a spurious cavity): refuse it when some face neighbour's outside region,
        // with the point filled, is enclosed within kPocketLimit voxels.
        if (ok && is_in && t.background >= 2) {
            flipped[e.point] = true;
            for (int k = 0; k < 6 && ok; ++k) {
                Vec3i q = c;
                q[k / 2] += (k % 2) ? 1 : -1;
                if (lat.contains(q) && !inside(q)) ok = !encloses_small_pocket(lat, inside, q);
            }
            flipped.erase(e.point);
        }
        if (!ok) {
            ++dropped;
            return true;
        }
        flipped[e.point] = is_in;
        return false;
    });
    return dropped;
}

RepairLoop::RepairLoop(SparseField& field, const Grid<float>& image_unit, const Grid<std::uint8_t>* roi,
                       const RepairOptions& options)
    : field_(field), image_unit_(image_unit), roi_(roi), options_(options), swarm_(options.swarm) {
    if (!(options.respawn_distance >= 0)) throw std::invalid_argument("the respawn distance must be >= 0");
    if (!(options.spawn_radius > 0)) throw std::invalid_argument("the spawn radius must be > 0");
    if (!(image_unit.dims() == field.lattice().dims())) throw std::invalid_argument("image and level set differ in size");
    if (roi && !(roi->dims() == field.lattice().dims())) throw std::invalid_argument("region of interest and level set differ in size");
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
        if (options_.topology_guard) out.log.guarded = guard_topology(field_, edits);
        out.log.modified = edits.size();
        if (!edits.empty()) {
            out.changed = field_.apply_edits(edits, RepairScope::kLocal);
            out.log.changed = out.changed.size();
        }
    }
    out.log.ms = std::chrono::duration<double, std::milli>(clock::now() - t0).count();
    return out;
}

std::vector<RepairStepLog> run_repair(SparseField& field, const Grid<float>& image_unit, const Grid<std::uint8_t>* roi,
                                      std::span<const RepairTarget> targets, const RepairOptions& options,
                                      const std::atomic<bool>* interrupt) {
    validate(options.swarm);
    if (options.steps < 0) throw std::invalid_argument("the number of repair steps must not be negative");
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
        while (next < order.size() && order[next].step <= step) loop.set_target(order[next++].position);
        RepairStepLog rec = loop.step().log;
        rec.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        log.push_back(rec);
    }
    return log;
}

}  // namespace liveset
