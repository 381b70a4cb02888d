// The hole-repair schedule (rounds aimed at the largest hole left, brush sized to it) and the sheet
// repair's local band.
#include "liveset/swarm/repair_schedule.hpp"

#include "liveset/eval/perforations.hpp"
#include "liveset/eval/topology.hpp"
#include "liveset/base/stopwatch.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

namespace liveset {

double hole_brush_range(std::size_t hole_voxels, double shell_thickness, double max_range) {
    if (!(std::isfinite(shell_thickness) && shell_thickness > 0))
        throw std::invalid_argument("hole brush: the shell thickness must be finite and > 0 voxels");
    if (!(std::isfinite(max_range) && max_range >= 3.0))
        throw std::invalid_argument("hole brush: the largest range must be finite and >= 3 voxels");
    const double radius = std::sqrt(static_cast<double>(hole_voxels) / (std::numbers::pi * shell_thickness));
    return std::clamp(radius + 1.0, 3.0, max_range);
}

void RepairScheduleOptions::validate() const {
    if (rounds < 0) throw std::invalid_argument("repair schedule: rounds must be >= 0");
    if (round_steps < 1) throw std::invalid_argument("repair schedule: round_steps must be >= 1");
    hole_brush_range(0, shell_thickness, max_range);  // throws on a bad brush sizing
}

namespace {

// The voxel of the hole region holding `start` (6-connected voxels with hole(q)) farthest from the
// mask, counted in face steps through the region from its voxels that touch the mask (ties: the
// one nearest `centroid`): the middle of the hole's widest opening. A large hole's centroid can lie
// where the rim has already grown shut while the opening that is left lies at its edge.
template <class InHole>
Vec3d deepest_voxel(const Grid<std::uint8_t>& mask, const InHole& hole, Vec3i start, Vec3d centroid) {
    const Lattice& lat = mask.lattice();
    std::unordered_set<PointIndex> region{lat.index(start)};
    std::vector<Vec3i> cells{start};
    for (std::size_t h = 0; h < cells.size(); ++h)
        for (int k = 0; k < 6; ++k) {
            Vec3i q = cells[h];
            q[k / 2] += (k % 2) ? 1 : -1;
            if (lat.contains(q) && hole(q) && region.insert(lat.index(q)).second) cells.push_back(q);
        }
    std::unordered_map<PointIndex, int> depth;  // breadth-first from the voxels touching the mask
    std::vector<Vec3i> queue;
    for (const Vec3i& c : cells)
        for (int k = 0; k < 6; ++k) {
            Vec3i q = c;
            q[k / 2] += (k % 2) ? 1 : -1;
            if (lat.contains(q) && mask(q)) {
                depth.emplace(lat.index(c), 1);
                queue.push_back(c);
                break;
            }
        }
    Vec3d best = start.cast<double>();
    int best_depth = -1;
    double best_d2 = 0;
    for (std::size_t h = 0; h < queue.size(); ++h) {
        const Vec3i c = queue[h];
        const int d = depth[lat.index(c)];
        const Vec3d off = c.cast<double>() - centroid;
        if (d > best_depth || (d == best_depth && dot(off, off) < best_d2)) {
            best = c.cast<double>(), best_depth = d, best_d2 = dot(off, off);
        }
        for (int k = 0; k < 6; ++k) {
            Vec3i q = c;
            q[k / 2] += (k % 2) ? 1 : -1;
            if (lat.contains(q) && region.count(lat.index(q)) && depth.emplace(lat.index(q), d + 1).second) queue.push_back(q);
        }
    }
    return best;
}

constexpr double kSameHole = 2.0;    // voxels: a hole's site this close to a round's target is that hole
constexpr double kMinShrink = 0.95;  // a round that leaves its hole with more than this share of its voxels stalled

// The hole to aim at: the largest (the finder's first) among those aimed at by the fewest stalled
// rounds — as a user whose click changed nothing clicks the next hole, and comes back later.
HoleSite next_target(const std::vector<HoleSite>& holes, const std::vector<Vec3d>& stalled) {
    const auto stalls = [&](const HoleSite& h) {
        return std::count_if(stalled.begin(), stalled.end(), [&](const Vec3d& s) { return norm(s - h.position) <= kSameHole; });
    };
    const HoleSite* best = &holes.front();
    long fewest = stalls(*best);
    for (const HoleSite& h : holes) {
        const long n = stalls(h);
        if (n < fewest) best = &h, fewest = n;
    }
    HoleSite out = *best;
    out.stalled_rounds = static_cast<int>(fewest);
    return out;
}

// Whether the round aimed at `target` shrank its hole: no hole of at least kMinShrink of its size is
// left at its site.
bool shrank(const HoleSite& target, const std::vector<HoleSite>& holes) {
    return std::none_of(holes.begin(), holes.end(), [&](const HoleSite& h) {
        return norm(h.position - target.position) <= kSameHole && static_cast<double>(h.voxels) > kMinShrink * static_cast<double>(target.voxels);
    });
}

}  // namespace

Grid<std::uint8_t> with_walled_inner(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& inner) {
    if (!(mask.dims() == inner.dims())) throw std::invalid_argument("walled inner: mask and inner differ in size");
    Grid<std::uint8_t> open(mask.lattice(), 0);
    for (PointIndex i = 0; i < open.size(); ++i) open[i] = inner[i] && !mask[i];
    std::size_t count = 0;
    const ComponentLabels label = label_components(open, 6, &count);
    std::vector<std::size_t> size(count + 1, 0);
    for (const std::uint32_t k : label) ++size[k];
    size[0] = 0;
    // The core: the largest piece (ties: the first in scan order, as label_components numbers them).
    const auto core = static_cast<std::uint32_t>(std::max_element(size.begin(), size.end()) - size.begin());
    Grid<std::uint8_t> out = mask;
    for (PointIndex i = 0; i < out.size(); ++i)
        if (label[i] != 0 && label[i] != core) out[i] = 1;
    return out;
}

std::vector<HoleSite> truth_hole_sites(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& truth, const Grid<std::uint8_t>& inner,
                                       HoleAim aim) {
    if (!(mask.dims() == truth.dims()) || !(mask.dims() == inner.dims()))
        throw std::invalid_argument("truth hole sites: mask, truth and inner differ in size");
    // Perforations and tunnels are read with the inner tissue the mask has walled off from the core
    // counted in (enclosed tissue, no place a hole leads to); the missed-truth regions are the same
    // (inner and truth do not overlap), sites and cavities are the mask's own.
    const Grid<std::uint8_t> enclosed = with_walled_inner(mask, inner);
    const auto missed = [&](Vec3i q) { return truth(q) && !mask(q); };
    const auto cavity = [&](Vec3i q) { return !mask(q); };
    const auto site = [&](const Perforation& p, const auto& in_hole) {
        return HoleSite{aim == HoleAim::kOpening ? deepest_voxel(mask, in_hole, p.nearest, p.centroid) : p.centroid, p.voxels};
    };
    std::vector<HoleSite> sites;
    for (const Perforation& p : find_perforations(enclosed, truth, inner)) sites.push_back(site(p, missed));
    if (sites.empty())
        for (const Perforation& p : find_cavities(mask, inner)) sites.push_back(site(p, cavity));
    if (sites.empty())
        for (const Perforation& p : find_missed_tunnels(enclosed, truth)) sites.push_back(site(p, missed));
    if (sites.empty())
        for (const Perforation& p : find_inner_handles(mask, inner)) sites.push_back(HoleSite{p.nearest.cast<double>(), p.voxels, 0, true});
    return sites;
}

void FieldRepairDriver::aim(const RepairOptions& options, Vec3d target) {
    loop_ = std::make_unique<RepairLoop>(field_, image_unit_, roi_, options);
    loop_->set_target(target);
}

RepairStepLog FieldRepairDriver::step() {
    if (!loop_) throw std::logic_error("FieldRepairDriver::step before aim");
    return loop_->step().log;
}

RepairScheduleResult run_repair_schedule(RepairDriver& driver, const RepairOptions& base, const RepairScheduleOptions& schedule,
                                         const HoleSiteFinder& find, const RoundSetup& setup, const std::atomic<bool>* interrupt) {
    schedule.validate();
    validate(base.swarm);
    if (!find) throw std::invalid_argument("repair schedule: no hole finder");
    const auto interrupted = [&] { return interrupt && interrupt->load(std::memory_order_relaxed); };
    RepairScheduleResult out;
    std::vector<Vec3d> stalled;  // targets of rounds after which their hole had not shrunk
    std::vector<HoleSite> holes = find(driver.field());
    for (int r = 0; r < schedule.rounds && !holes.empty(); ++r) {
        if (interrupted()) {
            out.interrupted = true;
            break;
        }
        RepairRoundLog round;
        round.target = next_target(holes, stalled);
        round.holes = holes.size();
        RepairOptions ro = base;
        ro.steps = schedule.round_steps;
        ro.swarm.seed = base.swarm.seed + static_cast<std::uint64_t>(r);
        ro.swarm.edit_range = hole_brush_range(round.target.voxels, schedule.shell_thickness, schedule.max_range);
        if (setup) setup(ro, round.target);
        if (round.target.cut) ro.swarm.decision = EditDecision::kCut;
        round.edit_range = ro.swarm.edit_range;
        driver.aim(ro, round.target.position);
        for (int step = 0; step < ro.steps && !interrupted(); ++step) {
            const auto t0 = std::chrono::steady_clock::now();
            const RepairStepLog l = driver.step();
            round.modified += l.modified;
            round.fragments += l.fragments;
            round.ms += ms_since(t0);
            ++round.steps;
        }
        out.rounds.push_back(round);
        holes = find(driver.field());
        if (!shrank(round.target, holes)) stalled.push_back(round.target.position);
    }
    out.holes_left = holes.size();
    return out;
}

RepairScheduleResult run_repair_schedule(SparseField& field, const Grid<float>& image_unit, const Grid<std::uint8_t>* roi,
                                         const RepairOptions& base, const RepairScheduleOptions& schedule,
                                         const HoleSiteFinder& find, const RoundSetup& setup, const std::atomic<bool>* interrupt) {
    FieldRepairDriver driver(field, image_unit, roi);
    return run_repair_schedule(driver, base, schedule, find, setup, interrupt);
}

std::pair<double, double> local_sheet_band(const Grid<float>& image_unit, const Grid<float>& phi, Vec3d site, double radius,
                                           double lower, double upper, double mean) {
    if (!(image_unit.dims() == phi.dims())) throw std::invalid_argument("local sheet band: image and level set differ in size");
    if (!(std::isfinite(radius) && radius > 0)) throw std::invalid_argument("local sheet band: the radius must be > 0");
    const Lattice& lat = phi.lattice();
    const int r = static_cast<int>(std::ceil(radius));
    const Vec3i c{static_cast<int>(std::lround(site.x)), static_cast<int>(std::lround(site.y)), static_cast<int>(std::lround(site.z))};
    std::vector<float> v;
    for (int dz = -r; dz <= r; ++dz)
        for (int dy = -r; dy <= r; ++dy)
            for (int dx = -r; dx <= r; ++dx) {
                const Vec3i q = c + Vec3i{dx, dy, dz};
                const Vec3d d = q.cast<double>() - site;
                if (!lat.contains(q) || dot(d, d) > radius * radius || !(phi(q) < 0.0f)) continue;
                const float x = image_unit(q);
                if (x >= lower && x < upper) v.push_back(x);
            }
    if (v.size() < 20) return {lower, upper};
    const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    const double shift = static_cast<double>(*mid) - mean;
    return {lower + shift, upper + shift};
}

}  // namespace liveset
