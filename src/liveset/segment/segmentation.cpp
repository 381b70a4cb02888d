// The segmentation loop with convergence detection by counting points that change side.
#include "liveset/segment/segmentation.hpp"

#include <chrono>
#include <cmath>
#include <deque>
#include <stdexcept>

#include "liveset/levelset/shapes.hpp"

namespace liveset {

void validate(const SegmentationOptions& o) {
    if (o.max_iterations < 1) throw std::invalid_argument("the iteration limit must be at least 1");
    if (o.window < 1) throw std::invalid_argument("the convergence window must be at least 1 iteration");
    if (!std::isfinite(o.tolerance) || o.tolerance < 0) throw std::invalid_argument("the convergence tolerance must be >= 0");
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

SegmentationResult run_segmentation(SparseField& field, const Speed& speed, const SegmentationOptions& options,
                                    const SegmentationHook& hook, const std::atomic<bool>* interrupt) {
    validate(options);
    using clock = std::chrono::steady_clock;
    const auto start = clock::now();
    const std::span<const float> phi = field.phi().values();
    std::vector<std::uint8_t> inside(phi.size());
    std::size_t inside_count = 0;
    for (std::size_t i = 0; i < phi.size(); ++i) inside_count += inside[i] = phi[i] < 0.0f;

    SegmentationResult result;
    std::deque<std::size_t> recent;
    for (int it = 1; it <= options.max_iterations; ++it) {
        if (interrupt && interrupt->load(std::memory_order_relaxed)) {
            result.reason = StopReason::kInterrupted;
            break;
        }
        if (field.zero_layer().empty()) {
            result.reason = StopReason::kVanished;
            break;
        }
        const auto t0 = clock::now();
        const StepResult step = field.step(speed, options.step);
        SegmentationProgress pr;
        pr.iteration = it;
        pr.dt = step.dt;
        pr.changed = step.changed.size();
        const std::span<const float> now = field.phi().values();
        for (PointIndex x : step.changed.points) {
            const std::uint8_t in = now[x] < 0.0f;
            if (in != inside[x]) {
                ++pr.flips;
                inside_count = in ? inside_count + 1 : inside_count - 1;
                inside[x] = in;
            }
        }
        pr.ms = std::chrono::duration<double, std::milli>(clock::now() - t0).count();
        pr.zero_layer = field.zero_layer().size();
        pr.band = field.band_size();
        pr.inside = inside_count;
        result.iterations = it;
        if (hook && !hook(pr, step.changed)) {
            result.reason = StopReason::kInterrupted;
            break;
        }
        // Net change of the inside count over the window: points oscillating across the front at
        // the edge of the threshold window cancel out, a front still advancing does not.
        recent.push_back(pr.inside);
        if (recent.size() > static_cast<std::size_t>(options.window) + 1) recent.pop_front();
        if (recent.size() == static_cast<std::size_t>(options.window) + 1) {
            const double net = std::abs(static_cast<double>(recent.back()) - static_cast<double>(recent.front()));
            if (net < std::max(1.0, options.tolerance * static_cast<double>(pr.zero_layer))) {
                result.reason = StopReason::kConverged;
                break;
            }
        }
        if (it == options.max_iterations) result.reason = StopReason::kIterationLimit;
    }
    result.inside = inside_count;
    result.seconds = std::chrono::duration<double>(clock::now() - start).count();
    return result;
}

void init_from_seeds(SparseField& field, std::span<const SeedBall> seeds) {
    std::vector<shapes::Sphere> spheres;
    for (const SeedBall& s : seeds) spheres.emplace_back(s.center, std::max(s.radius, 0.5));
    const shapes::SeedSpheres sdf(field.lattice(), std::move(spheres));
    field.init_from_sdf(sdf);
}

Grid<std::uint8_t> inside_mask(const Grid<float>& phi, const Grid<std::uint8_t>* roi) {
    if (roi && !(roi->dims() == phi.dims())) throw std::invalid_argument("region-of-interest mask does not match phi");
    Grid<std::uint8_t> m(phi.lattice());
    for (std::size_t i = 0; i < phi.size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        m[p] = phi[p] < 0.0f && (!roi || (*roi)[p] != 0);
    }
    return m;
}

}  // namespace liveset
