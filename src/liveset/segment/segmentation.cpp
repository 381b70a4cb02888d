// The segmentation loop with convergence detection by counting points that change side.
#include "liveset/segment/segmentation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "liveset/levelset/shapes.hpp"
#include "liveset/base/stopwatch.hpp"
#include "liveset/segment/voxel_loops.hpp"

namespace liveset {

void validate(const SegmentationOptions& o) {
    if (o.max_iterations < 1) throw std::invalid_argument("the iteration limit must be at least 1");
    if (o.window < 1) throw std::invalid_argument("the convergence window must be at least 1 iteration");
    if (!std::isfinite(o.tolerance) || o.tolerance < 0) throw std::invalid_argument("the convergence tolerance must be >= 0");
    validate(o.step);
}

std::string to_string(StopReason reason) {
    switch (reason) {
        case StopReason::kConverged: return "converged";
        case StopReason::kIterationLimit: return "iteration limit";
        case StopReason::kInterrupted: return "interrupted";
        case StopReason::kVanished: return "the front vanished";
    }
    return "unknown";
}

FrontConvergence::FrontConvergence(const Grid<float>& phi, const SegmentationOptions& options)
    : window_(options.window), tolerance_(options.tolerance) {
    validate(options);
    const std::span<const float> values = phi.values();
    inside_.resize(values.size());
    std::uint8_t* const inside = inside_.data();  // each element written from its own index: on every thread
    inside_count_ = voxel_loops::count_if(values.size(), [&](std::size_t i) { return (inside[i] = values[i] < 0.0f) != 0; });
}

std::size_t FrontConvergence::record_step(const Grid<float>& phi, std::span<const PointIndex> candidates) {
    std::size_t flips = 0;
    for (PointIndex x : candidates) {
        const std::uint8_t in = phi[x] < 0.0f;
        if (in != inside_[x]) {
            ++flips;
            inside_count_ = in ? inside_count_ + 1 : inside_count_ - 1;
            inside_[x] = in;
        }
    }
    return flips;
}

bool FrontConvergence::converged(std::size_t zero_layer) {
    recent_.push_back(inside_count_);
    if (recent_.size() > static_cast<std::size_t>(window_) + 1) recent_.pop_front();
    if (recent_.size() < static_cast<std::size_t>(window_) + 1) return false;
    const double net = std::abs(static_cast<double>(recent_.back()) - static_cast<double>(recent_.front()));
    return net < std::max(1.0, tolerance_ * static_cast<double>(zero_layer));
}

SegmentationRun::SegmentationRun(SparseField& field, const Speed& speed, const SegmentationOptions& options)
    : field_(field), speed_(speed), options_(options), convergence_(field.phi(), options) {
    result_.inside = convergence_.inside();
}

bool SegmentationRun::advance(const SegmentationHook& hook) {
    if (ended_) return false;
    using clock = std::chrono::steady_clock;
    const auto t0 = clock::now();
    const auto end = [&](StopReason reason) {
        result_.reason = reason;
        ended_ = true;
    };
    if (field_.zero_layer().empty()) {
        end(StopReason::kVanished);
    } else {
        const int it = ++result_.iterations;
        const StepResult step = field_.step(speed_, options_.step);
        SegmentationProgress pr;
        pr.iteration = it;
        pr.dt = step.dt;
        pr.changed = step.changed.size();
        pr.awake = step.awake;
        pr.flips = convergence_.record_step(field_.phi(), step.changed.sign_changes.value());  // only steps change the field here
        pr.ms = ms_since(t0);
        pr.zero_layer = field_.zero_layer().size();
        pr.band = field_.band_size();
        pr.inside = convergence_.inside();
        result_.inside = pr.inside;
        if (hook && !hook(pr, step.changed)) end(StopReason::kInterrupted);
        else if (convergence_.converged(pr.zero_layer)) end(StopReason::kConverged);
        else if (it == options_.max_iterations) end(StopReason::kIterationLimit);
    }
    return !ended_;
}

void SegmentationRun::interrupt() {
    if (ended_) return;
    result_.reason = StopReason::kInterrupted;
    ended_ = true;
}

SegmentationResult run_segmentation(SparseField& field, const Speed& speed, const SegmentationOptions& options,
                                    const SegmentationHook& hook, const std::atomic<bool>* interrupt) {
    const auto start = std::chrono::steady_clock::now();
    SegmentationRun run(field, speed, options);
    for (;;) {
        if (interrupt && interrupt->load(std::memory_order_relaxed)) run.interrupt();
        if (!run.advance(hook)) break;
    }
    SegmentationResult result = run.result();
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

void init_from_seeds(SparseField& field, std::span<const SeedBall> seeds) {
    std::vector<shapes::Sphere> spheres;
    for (const SeedBall& s : seeds) spheres.emplace_back(s.center, std::max(s.radius, 0.5));
    const shapes::SeedSpheres sdf(field.lattice(), std::move(spheres));  // validates them
    // Outside the seeds' bounding box, grown by the far value N + 1 (and a point for rounding),
    // every sphere's distance is above N + 1: only the box is evaluated, not the whole lattice
    // (the eight BrainWeb seeds span a quarter of its 7 M voxels).
    const double reach = field.layers() + 2.0;
    const Vec3i d = field.lattice().dims();
    Vec3i lo = d, hi{0, 0, 0};
    for (const shapes::Sphere& s : sdf.seeds)
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], static_cast<int>(std::clamp(std::floor(s.center[a] - s.radius - reach), 0.0, d[a] - 1.0)));
            hi[a] = std::max(hi[a], static_cast<int>(std::clamp(std::ceil(s.center[a] + s.radius + reach), 0.0, d[a] - 1.0)));
        }
    field.init_from_sdf(sdf, lo, hi);
}

void unite_seeds(SparseField& field, std::span<const SeedBall> seeds) {
    for (const SeedBall& s : seeds) {
        const shapes::Sphere ball(s.center, std::max(s.radius, 0.5));
        const double reach = ball.radius + field.layers() + 1.0;  // beyond it the ball cannot undercut φ
        const Vec3d lo = s.center - Vec3d{reach, reach, reach}, hi = s.center + Vec3d{reach, reach, reach};
        field.unite_in_box({static_cast<int>(std::floor(lo.x)), static_cast<int>(std::floor(lo.y)), static_cast<int>(std::floor(lo.z))},
                           {static_cast<int>(std::ceil(hi.x)), static_cast<int>(std::ceil(hi.y)), static_cast<int>(std::ceil(hi.z))}, ball);
    }
}

Grid<std::uint8_t> inside_mask(const Grid<float>& phi, const Grid<std::uint8_t>* roi) {
    if (roi && !(roi->dims() == phi.dims())) throw std::invalid_argument("region-of-interest mask does not match phi");
    Grid<std::uint8_t> m(phi.lattice());
    voxel_loops::for_each(phi.size(), [&](std::size_t i) {
        const auto p = static_cast<PointIndex>(i);
        m[p] = phi[p] < 0.0f && (!roi || (*roi)[p] != 0);
    });
    return m;
}

}  // namespace liveset
