// The incremental global step: the same Δφ as the full-band step, applied only where it moves a
// zero-layer value, and re-layered only around those points (see sparse_field.hpp).
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdint>

#include "liveset/levelset/sparse_field.hpp"

namespace liveset {

StepResult SparseField::step_incremental(const Speed& speed, const StepOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    StepResult result;
    const auto zero = zero_layer();
    result.zero_layer = zero.size();
    const std::vector<double> rate = zero_rates(speed);
    result.dt = time_step(rate, speed, options);

    // Δ exactly as the full-band step computes it; only points whose bits change become edits
    // (a Δ that rounds away, or a point already at the bound, changes nothing downstream).
    std::vector<std::uint8_t> moves(zero.size(), 0);
    std::vector<float> delta(zero.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, zero.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t n = r.begin(); n != r.end(); ++n) {
            const float d = static_cast<float>(std::clamp(result.dt * rate[n], -0.5, 0.5));
            const float v = phi_[zero[n]];
            delta[n] = d;
            moves[n] = std::bit_cast<std::uint32_t>(v + d) != std::bit_cast<std::uint32_t>(v);
        }
    });
    std::vector<ZeroLayerEdit> edits;
    for (std::size_t n = 0; n < zero.size(); ++n)
        if (moves[n]) edits.push_back({zero[n], delta[n]});
    result.changed = repair_band(edits, RepairScope::kLocal);
    last_update_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace liveset
