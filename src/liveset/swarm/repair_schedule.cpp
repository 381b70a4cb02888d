// The hole-repair schedule (rounds aimed at the largest hole left, brush sized to it) and the sheet
// repair's local band.
#include "liveset/swarm/repair_schedule.hpp"

#include "liveset/eval/perforations.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>

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

std::vector<HoleSite> truth_hole_sites(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& truth, const Grid<std::uint8_t>& inner) {
    std::vector<Perforation> h = find_perforations(mask, truth, inner);
    if (h.empty()) h = find_cavities(mask, inner);
    if (h.empty()) h = find_missed_tunnels(mask, truth);
    std::vector<HoleSite> sites;
    for (const Perforation& p : h) sites.push_back({p.centroid, p.voxels});
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
    std::vector<HoleSite> holes = find(driver.field());
    for (int r = 0; r < schedule.rounds && !holes.empty(); ++r) {
        if (interrupted()) {
            out.interrupted = true;
            break;
        }
        RepairRoundLog round;
        round.target = holes.front();
        round.holes = holes.size();
        RepairOptions ro = base;
        ro.steps = schedule.round_steps;
        ro.swarm.seed = base.swarm.seed + static_cast<std::uint64_t>(r);
        ro.swarm.edit_range = hole_brush_range(round.target.voxels, schedule.shell_thickness, schedule.max_range);
        if (setup) setup(ro, round.target);
        round.edit_range = ro.swarm.edit_range;
        driver.aim(ro, round.target.position);
        for (int step = 0; step < ro.steps && !interrupted(); ++step) {
            const auto t0 = std::chrono::steady_clock::now();
            const RepairStepLog l = driver.step();
            round.modified += l.modified;
            round.fragments += l.fragments;
            round.ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
            ++round.steps;
        }
        out.rounds.push_back(round);
        holes = find(driver.field());
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
