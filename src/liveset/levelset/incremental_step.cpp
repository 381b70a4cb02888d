// The incremental global step: the same Δφ as the full-band step, applied only where it moves a
// zero-layer value and re-layered only around those points; with sleeping on, only at the awake
// zero-layer points (see sparse_field.hpp and activity.hpp); when most of a small front moves,
// the whole band (repair_dense).
#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <span>

#include "liveset/levelset/band_detail.hpp"
#include "liveset/levelset/sparse_field.hpp"
#include "liveset/base/stopwatch.hpp"

namespace liveset {

StepResult SparseField::step_incremental(const Speed& speed, const StepOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    // Once an eighth of the zero-layer list has been reordered by insertions and removals, it goes
    // back into lattice order, so that the scan below walks φ and the activity blocks mostly
    // forwards (BrainWeb: -8 % CPU; never sorting makes the box flow 1.5x slower per step).
    if (zero_reordered_ * 8 >= zero_layer().size()) sort_lists(true);
    StepResult result;
    const auto zero = zero_layer();
    result.zero_layer = zero.size();
    const int sleep_after = options.sleep_after;
    if (sleep_after > 0) activity_.begin_step(lattice(), speed.serial(), steps_);

    // Rates at the awake points (all of them when sleeping is off), exactly as zero_rates(). A
    // sleeping point costs only its awake test: each 4 096-point chunk of the zero layer (one chunk
    // on one thread) keeps its awake points and their rates in its own arrays, joined in chunk
    // order (the zero layer's order, whatever the thread count), so the passes below run over the
    // awake points only.
    struct Rates {
        std::vector<std::uint32_t> at;  // positions in the zero layer
        std::vector<double> rate;
    };
    // The awake test reads the block stamps through locals (a store to the lists below could
    // alias the members) and is skipped while everything is awake; a point is a store and a count.
    const FrontActivity::AwakeTest awake =
        sleep_after > 0 ? activity_.awake_test(steps_, sleep_after) : FrontActivity::AwakeTest{};
    auto rates = detail::ordered_chunks<Rates>(zero.size(), [&](std::size_t b, std::size_t e, Rates& out) {
        // Buffers for every point, not filled first: late in a run most points sleep, and the
        // zero layer is hundreds of thousands of points.
        const auto at = std::make_unique_for_overwrite<std::uint32_t[]>(e - b);
        const auto points = std::make_unique_for_overwrite<PointIndex[]>(e - b);
        FrontActivity::AwakeScan is_awake(awake, lattice());
        std::size_t n_awake = 0;
        for (std::size_t n = b; n < e; ++n) {
            at[n_awake] = static_cast<std::uint32_t>(n);
            points[n_awake] = zero[n];
            n_awake += is_awake(zero[n]) ? 1 : 0;
        }
        out.at.assign(at.get(), at.get() + n_awake);
        out.rate.resize(n_awake);
        speed.rates(phi_, std::span<const PointIndex>(points.get(), n_awake), out.rate);
    });
    std::vector<std::uint32_t> at;
    std::vector<double> rate;
    detail::join_parts(rates, &Rates::at, at);
    detail::join_parts(rates, &Rates::rate, rate);
    result.awake = at.size();
    result.dt = time_step(rate, speed, options);  // sleeping points do not bound it

    // Δ exactly as the full-band step computes it; only points whose bits change become edits
    // (a Δ that rounds away, or a point already at the bound, changes nothing downstream).
    struct Part {
        std::vector<ZeroLayerEdit> edits;
    };
    auto parts = detail::ordered_chunks<Part>(at.size(), [&](std::size_t b, std::size_t e, Part& out) {
        for (std::size_t m = b; m < e; ++m) {
            const PointIndex i = zero[at[m]];
            const float d = static_cast<float>(std::clamp(result.dt * rate[m], -0.5, 0.5));
            const float v = phi_[i];
            if (std::bit_cast<std::uint32_t>(v + d) != std::bit_cast<std::uint32_t>(v)) out.edits.push_back({i, d});
        }
    });
    std::vector<ZeroLayerEdit> edits;
    detail::join_parts(parts, &Part::edits, edits);
    // Local and global re-layering give the same bits (sparse_field.hpp); when most of a small
    // front moves, most of the band changes and a whole-band repair is the cheaper one
    // (repair_dense: the push sweep, or changes of layer and a value pass when few points change
    // layer).
    const bool dense = !edits.empty() && zero.size() <= options.dense_front_max && 5 * edits.size() >= 3 * zero.size();
    result.whole_band = dense;
    result.value_pass = dense && pass_next_;  // repair_dense's choice
    const FrontRule rule{speed, result.dt, options.cfl};
    const FrontRule* const thin = options.thin_fronts ? &rule : nullptr;
    result.changed = dense ? repair_dense(edits, thin) : repair_band(edits, RepairScope::kLocal, thin);
    last_update_ms_ = ms_since(start);
    return result;
}

// A dense step's repair (sparse_field.hpp): the same bits either way.
ChangedPoints SparseField::repair_dense(std::span<const ZeroLayerEdit> edits, const FrontRule* rule) {
    if (!pass_next_ || edits.empty()) return repair_band(edits, RepairScope::kGlobal, rule);
    std::vector<RegionPoint>& region = region_.v;
    region.clear();
    move_zero_layer(edits, region, rule);
    std::vector<PointIndex> pulled;  // X: the value pass's points, then the region's
    pulled.reserve(band_size() + region.size());
    relayer_changes(region, &pulled);
    std::size_t layer_changes = 0;
    ChangedPoints changed = finish(region, false, &layer_changes);
    pass_next_ = few_layer_changes(layer_changes);
    pulled.insert(pulled.end(), changed.points.begin(), changed.points.end());  // the pass changes no sign
    changed.points.swap(pulled);
    return changed;
}

}  // namespace liveset
