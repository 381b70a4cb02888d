// The incremental global step: the same Δφ as the full-band step, applied only where it moves a
// zero-layer value and re-layered only around those points; with sleeping on, only at the awake
// zero-layer points (see sparse_field.hpp and activity.hpp).
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdint>

#include "liveset/grid/sampling.hpp"
#include "liveset/levelset/sparse_field.hpp"

namespace liveset {

namespace {

template <class F>
void parallel_chunks(std::size_t n, F&& f) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 2048), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
    });
}

}  // namespace

StepResult SparseField::step_incremental(const Speed& speed, const StepOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    StepResult result;
    const auto zero = zero_layer();
    result.zero_layer = zero.size();
    const int sleep_after = options.sleep_after;
    if (sleep_after > 0) activity_.begin_step(lattice(), speed.serial(), steps_);

    // Rates at the awake points (all of them when sleeping is off), exactly as zero_rates().
    std::vector<double> rate(zero.size(), 0.0);
    std::vector<std::uint8_t> awake(zero.size(), 1);
    parallel_chunks(zero.size(), [&](std::size_t n) {
        const Vec3i p = decoder_.coord(zero[n]);
        if (sleep_after > 0 && !activity_.awake(p, steps_, sleep_after)) {
            awake[n] = 0;
            return;
        }
        const SpeedSample s = speed.at(phi_, p);
        double r = 0.0;
        if (s.propagation != 0.0f) r += static_cast<double>(s.propagation) * upwind_gradient_norm(phi_, p, s.propagation);
        if (s.curvature != 0.0f) r += static_cast<double>(s.curvature) * norm(central_gradient(phi_, p));
        rate[n] = r;
    });
    result.dt = time_step(rate, speed, options);  // sleeping points (rate 0) do not bound it

    // Δ exactly as the full-band step computes it; only points whose bits change become edits
    // (a Δ that rounds away, or a point already at the bound, changes nothing downstream).
    std::vector<float> delta(zero.size());
    parallel_chunks(zero.size(), [&](std::size_t n) {
        if (!awake[n]) return;
        const float d = static_cast<float>(std::clamp(result.dt * rate[n], -0.5, 0.5));
        const float v = phi_[zero[n]];
        delta[n] = d;
        awake[n] = std::bit_cast<std::uint32_t>(v + d) != std::bit_cast<std::uint32_t>(v) ? 2 : 1;
    });
    std::vector<ZeroLayerEdit> edits;
    for (std::size_t n = 0; n < zero.size(); ++n) {
        result.awake += awake[n] != 0;
        if (awake[n] == 2) edits.push_back({zero[n], delta[n]});
    }
    result.changed = repair_band(edits, RepairScope::kLocal);
    last_update_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace liveset
