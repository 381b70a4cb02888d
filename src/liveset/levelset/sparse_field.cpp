// SparseField implementation: the global step and the shared order-independent band repair up to
// the re-layering (initialisation in initialise.cpp; re-layering in relayer.cpp; local edits and
// undo in local_edits.cpp; the scheme in sparse_field.hpp).
#include "liveset/levelset/sparse_field.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <span>
#include <string>
#include <utility>

#include "liveset/grid/radix_sort.hpp"
#include "liveset/levelset/band_detail.hpp"
#include "liveset/levelset/layer_value.hpp"
#include "liveset/base/stopwatch.hpp"

namespace liveset {

namespace {

using detail::for_each_neighbor6;
using detail::is_temp;
using detail::kPendNeg;
using detail::kNoSlot;
using detail::kPendPos;
using detail::kPendZero;
using detail::parallel_range;
using detail::point_text;

// Each point's position in its layer list, into the slot lattice (prefetched: the points are
// scattered over it).
void write_slots(std::span<const PointIndex> list, std::uint32_t* slot) {
    for (std::size_t k = 0; k < list.size(); ++k) {
        if (k + detail::kAhead < list.size()) __builtin_prefetch(slot + list[k + detail::kAhead], 1);
        slot[list[k]] = static_cast<std::uint32_t>(k);
    }
}

}  // namespace

SparseField::SparseField(const Lattice& lattice, int layers) : layers_(layers) {
    if (layers < 1 || layers > kMaxLayers)
        throw std::invalid_argument("number of layers must be between 1 and " + std::to_string(kMaxLayers) +
                                    ", got " + std::to_string(layers));
    phi_ = Grid<float>(lattice, static_cast<float>(layers + 1));
    status_ = Grid<std::int8_t>(lattice, far_outside());
    slot_ = Grid<std::uint32_t>(lattice, kNoSlot);
    decoder_ = IndexDecoder(lattice);
    lists_.assign(2 * static_cast<std::size_t>(layers) + 1, {});
    for (int z = -layers; z <= layers; ++z)
        for (int y = -layers; y <= layers; ++y)
            for (int x = -layers; x <= layers; ++x)
                if (std::abs(x) + std::abs(y) + std::abs(z) <= layers) ball_.push_back({x, y, z});
}

std::span<const PointIndex> SparseField::layer(int k) const {
    if (k < -layers_ || k > layers_) throw std::out_of_range("layer index out of range");
    return lists_[static_cast<std::size_t>(k + layers_)];
}

std::size_t SparseField::band_size() const {
    std::size_t n = 0;
    for (const auto& l : lists_) n += l.size();
    return n;
}

void SparseField::list_add(PointIndex i, int layer) {
    auto& list = lists_[static_cast<std::size_t>(layer + layers_)];
    slot_[i] = static_cast<std::uint32_t>(list.size());
    list.push_back(i);
    if (layer == 0) ++zero_reordered_;
}

void SparseField::list_remove(PointIndex i, int layer) {
    auto& list = lists_[static_cast<std::size_t>(layer + layers_)];
    const std::uint32_t pos = slot_[i];
    const PointIndex last = list.back();
    list[pos] = last;
    slot_[last] = pos;
    list.pop_back();
    slot_[i] = kNoSlot;
    if (layer == 0) ++zero_reordered_;
}

// ---------------------------------------------------------------------------------------------
// Global step

void validate(const StepOptions& o) {
    if (!(o.cfl > 0.0f) || o.cfl > 0.5f || !std::isfinite(o.cfl)) throw std::invalid_argument("CFL number must be in (0, 0.5]");
    if (!(o.max_dt > 0.0f)) throw std::invalid_argument("maximum time step must be positive");
    if (o.mode != StepMode::kFullBand && o.mode != StepMode::kIncremental) throw std::invalid_argument("unknown step mode");
    if (o.sleep_after < 0 || o.sleep_after > 1'000'000)
        throw std::invalid_argument("steps before a still stretch of front sleeps must be in [0, 1000000] (0: never)");
    if (o.dense_front_max > 1'000'000'000)
        throw std::invalid_argument("largest front re-layered whole must be at most 1000000000 points (0: never)");
    if (o.parallel_band_min > 1'000'000'000)
        throw std::invalid_argument("smallest band stepped on several threads must be at most 1000000000 points (0: always)");
    if (o.sleep_after > 0 && o.mode != StepMode::kIncremental)
        throw std::invalid_argument("sleeping stretches of front need the incremental step (StepMode::kIncremental)");
}

std::vector<double> SparseField::zero_rates(const Speed& speed) const {
    const auto zero = zero_layer();
    std::vector<double> rate(zero.size());
    detail::for_chunks(zero.size(), [&](std::size_t b, std::size_t e) {
        speed.rates(phi_, zero.subspan(b, e - b), std::span(rate).subspan(b, e - b));
    });
    return rate;
}

// 1 / h_min of the voxel sizes as the curvature takes them (Lattice::spacing_float): 1 at 1 mm.
double SparseField::parabolic_factor() const {
    const Vec3f h = phi_.lattice().spacing_float();
    return 1.0 / static_cast<double>(std::min({h.x, h.y, h.z}));
}

double SparseField::time_step(std::span<const double> rate, const Speed& speed, const StepOptions& options) const {
    double max_rate = 0.0;
    for (double r : rate) {
        if (!std::isfinite(r)) throw std::runtime_error("speed term returned a non-finite value");
        max_rate = std::max(max_rate, std::abs(r));
    }
    double dt = options.max_dt;
    if (max_rate > 0.0) dt = std::min(dt, static_cast<double>(options.cfl) / max_rate);
    // The parabolic bound (docs/ARCHITECTURE.md, "Time step"): the difference-of-normals curvature
    // (per millimetre) times |∇φ| per finest voxel, linearised about a front with |∇φ| = 1 in index
    // units, has eigenvalues of magnitude at most 8/h_min over every frequency and normal, h the voxel
    // sizes in mm (scripts/parabolic_bound.py --spacing; the checkerboard along the front across the
    // finest axes reaches it: 8 at 1 mm), so forward Euler keeps every mode's amplification
    // |1 − 8·w·f·dt| ≤ 1 up to w·f·dt = 1/4, f = 1/h_min.
    if (speed.curvature_weight() > 0.0f) dt = std::min(dt, 1.0 / (4.0 * speed.curvature_weight() * parabolic_factor()));
    return dt;
}

std::vector<ZeroLayerEdit> SparseField::compute_step(const Speed& speed, const StepOptions& options,
                                                     double* dt_out) const {
    validate(options);
    const auto zero = zero_layer();
    const std::vector<double> rate = zero_rates(speed);
    const double dt = time_step(rate, speed, options);
    std::vector<ZeroLayerEdit> edits(zero.size());
    parallel_range(zero.size(), [&](std::size_t n) {
        edits[n] = {zero[n], static_cast<float>(std::clamp(dt * rate[n], -0.5, 0.5))};
    });
    if (dt_out != nullptr) *dt_out = dt;
    return edits;
}

namespace {

// Ascending order by LSD radix sort on bytes, skipping the bytes no index uses: a layer list of
// n points sorts in a few linear passes (std::sort was 8 % of a BrainWeb segmentation).
template <class List>
void sort_indices(List& v, List& scratch) {
    if (v.size() < 256) {
        std::sort(v.begin(), v.end());
        return;
    }
    stable_radix_sort(v, [](PointIndex i) { return i; }, scratch);
}

}  // namespace

void SparseField::sort_lists(bool zero_only) {
    zero_reordered_ = 0;
    auto& scratch = sort_scratch_.v;  // kept: a list-sized buffer is not faulted in every sort
    for (auto& list : lists_) {
        if (zero_only && &list != &lists_[static_cast<std::size_t>(layers_)]) continue;
        sort_indices(list, scratch);
        if (!slots_stale_) write_slots(list, slot_.values().data());  // else ensure_slots writes them all
    }
}

void SparseField::ensure_slots() {
    if (!slots_stale_) return;
    std::uint32_t* const slot = slot_.values().data();
    detail::for_each_list(2 * layers_ + 1, band_size() >= detail::kParallelMin, [&](std::size_t l) { write_slots(lists_[l], slot); });
    slots_stale_ = false;
}

StepResult SparseField::step(const Speed& speed, const StepOptions& options) {
    validate(options);
    ++steps_;
    StepResult result;
    const auto run = [&] {
        result = options.mode == StepMode::kFullBand ? step_full_band(speed, options) : step_incremental(speed, options);
    };
    if (band_size() < options.parallel_band_min) {
        // One slot, one arena per calling thread: fields stepped on other threads never wait for it.
        thread_local tbb::task_arena alone(1);
        struct NoSplit {  // no level split for two tasks in this step, whatever it throws
            bool& split;
            explicit NoSplit(bool& s) : split(s) { split = false; }
            ~NoSplit() { split = true; }
        } no_split(split_levels_);
        alone.execute(run);
    } else {
        run();
    }
    activity_.wake_near(result.changed.sign_changes.value(), lattice(), steps_);  // a no-op until a sleeping step ran
    return result;
}

StepResult SparseField::step_full_band(const Speed& speed, const StepOptions& options) {
    StepResult result;
    result.zero_layer = zero_layer().size();
    result.awake = result.zero_layer;
    result.whole_band = true;
    const auto edits = compute_step(speed, options, &result.dt);
    const FrontRule rule{speed, result.dt, options.cfl};
    result.changed = commit(edits, RepairScope::kGlobal, options.thin_fronts ? &rule : nullptr);
    // The repair leaves the zero list in lattice order and the outer lists in the order the sweep
    // claimed them (near lattice order); every few steps all of them are put back in lattice order.
    if (++steps_since_sort_ >= 8) {
        sort_lists();
        steps_since_sort_ = 0;
    }
    return result;
}

// ---------------------------------------------------------------------------------------------
// The shared repair

ChangedPoints SparseField::commit(std::span<const ZeroLayerEdit> edits, RepairScope scope, const FrontRule* rule) {
    const auto start = std::chrono::steady_clock::now();
    ChangedPoints changed = repair_band(edits, scope, rule);
    last_update_ms_ = ms_since(start);
    return changed;
}

namespace {

// Where a pinned point's value may lie (the thin-front rule, thin_front.cpp): within 0.25 of its
// side's edge of the zero layer. Without a branch (a moving front's values are unpredictable).
bool near_edge(float w) {
    const float a = std::abs(w);
    return static_cast<bool>(static_cast<unsigned>(a >= 0.25f) & static_cast<unsigned>(a <= 0.5f));
}

// Step 1 of the repair for edits [b, e) (see move_zero_layer): the new values, the old ones kept,
// every move 0, and the edits whose new value leaves [-0.5, 0.5] listed in order from leaving[b];
// returns how many. With `near_edges` (the thin-front rule), the points whose value changed and
// stays near its side's edge (near_edge: in the zero layer) are listed in order from near[b],
// *n_near how many. A store and a count each, no branch (whether a point leaves is unpredictable).
// Locals and parameters only: a store through std::int8_t may alias anything, so values read
// through a closure would be reloaded after every store.
template <bool near_edges>
std::size_t move_values(const ZeroLayerEdit* edits, std::size_t b, std::size_t e, float* phi, float* old_phi,
                        std::int8_t* move, std::uint32_t* leaving, PointIndex* near, std::size_t* n_near) {
    std::size_t n = b, m = b;
    for (std::size_t k = b; k < e; ++k) {
        const PointIndex i = edits[k].point;
        const float v = phi[i];
        const float moved = v + edits[k].delta;
        old_phi[k] = v;
        phi[i] = moved;
        move[k] = 0;
        leaving[n] = static_cast<std::uint32_t>(k);
        n += std::abs(moved) > 0.5f ? 1 : 0;
        if constexpr (near_edges) {
            near[m] = i;
            m += static_cast<unsigned>(near_edge(moved)) & static_cast<unsigned>(!detail::same_bits(moved, v));
        }
    }
    if constexpr (near_edges) *n_near = m - b;
    return n - b;
}

// Step 2 for the leaving edits `leaving` (see move_zero_layer): +1 leaves outwards, -1 inwards,
// +2 / -2 would leave but is blocked, +3 / -3 likewise and has no L∓1 neighbour on the other side
// (which the thin-front rule would look at: it has nothing to hand over, and its neighbours are
// read here anyway). Reads only, after every value of step 1 is written.
void classify_moves(const ZeroLayerEdit* edits, std::span<const std::uint32_t> leaving, const float* phi,
                    const std::int8_t* status, const Lattice& lattice, const IndexDecoder& index_decoder,
                    std::int8_t* move) {
    const Lattice lat = lattice;
    const IndexDecoder decoder = index_decoder;
    const detail::Neighbors6 around(lat, decoder);  // its prefetch only
    for (std::size_t j = 0; j < leaving.size(); ++j) {
        if (j + detail::kAhead < leaving.size()) around.prefetch(phi, status, edits[leaving[j + detail::kAhead]].point);
        const std::uint32_t k = leaving[j];
        const PointIndex i = edits[k].point;
        const bool up = phi[i] > 0.5f;
        // Without a branch per neighbour (a moving band's statuses and values are unpredictable):
        // a zero-layer neighbour beyond -0.5 (leaving inwards) blocks an outward move, and back.
        // On the other side's values, x > 0.5 is -x < -0.5 bit for bit.
        const float flip = up ? 1.0f : -1.0f;
        const std::int8_t other = up ? std::int8_t{-1} : std::int8_t{1};
        unsigned blocked = 0, ahead = 0;
        for_each_neighbor6(lat, decoder, i, [&](PointIndex q) {
            blocked |= static_cast<unsigned>(status[q] == 0) & static_cast<unsigned>(flip * phi[q] < -0.5f);
            ahead |= static_cast<unsigned>(status[q] == other);
        });
        const int m = blocked == 0 ? 1 : ahead != 0 ? 2 : 3;
        move[k] = static_cast<std::int8_t>(up ? m : -m);
    }
}

}  // namespace

ChangedPoints SparseField::repair_band(std::span<const ZeroLayerEdit> edits, RepairScope scope, const FrontRule* rule) {
    if (edits.empty()) return {{}, std::vector<PointIndex>{}};
    std::vector<RegionPoint>& region = region_.v;
    region.clear();
    move_zero_layer(edits, region, rule);

    // 4-5. Outer layers from the new zero layer: a local update re-layers outwards from the
    //    changed points only (relayer_changes, relayer.cpp); a global one the whole band,
    //    and the far points it reaches. 6. Bookkeeping and the change report.
    if (scope == RepairScope::kLocal) {
        relayer_changes(region);
    } else {
        // The whole band is re-layered. Its lists are rebuilt from the sweep's levels (relist)
        // when the last whole-band repair changed the layer of at least an eighth of its
        // region, else its points are moved between them: rebuilding costs a slot per band point
        // and a sort of the zero list, moving two slot updates per point that changed layer, and a
        // front growing from seeds changes 15-27 % per step (BrainWeb), the box under curvature
        // flow 0-10 % (docs/BENCHMARKS.md, sessions 36-37). Decided before the sweep, so that
        // neither way pays for the other's records (the levels, the moves).
        // A rebuilding repair puts the new zero layer in lattice order first: the zero list then,
        // and the sweep's first sources, run forwards through memory (the sort is needed for the
        // zero list anyway; before the sweep it gains at most a few per cent, session 37).
        PointList& zero = collect_band(region);
        const bool rebuild = relist_next_;
        if (rebuild) sort_indices(zero, sort_scratch_.v);
        sweep_whole_band(region, zero, /*keep_levels=*/rebuild);
        std::size_t layer_changes = 0;
        ChangedPoints changed = finish(region, rebuild, &layer_changes);
        if (rebuild) relist(zero);
        relist_next_ = 8 * layer_changes >= region.size();
        pass_next_ = few_layer_changes(layer_changes);
        return changed;
    }
    return finish(region);
}

// Steps 1-3 (sparse_field.hpp). The loops run over raw pointers and write the region through a
// buffer sized first, without a branch on what a point does (unpredictable in a moving front):
// each writes its entry and counts it or not.
void SparseField::move_zero_layer(std::span<const ZeroLayerEdit> edits, std::vector<RegionPoint>& region,
                                  const FrontRule* rule) {
    const std::size_t n = edits.size();
    float* const phi = phi_.values().data();
    std::int8_t* const status = status_.values().data();
    const Lattice lat = lattice();
    const IndexDecoder decoder = decoder_;
    if (old_phi_.v.size() < n) old_phi_.v.resize(n);  // kept between updates, never shrunk
    if (move_.v.size() < n) move_.v.resize(n);
    if (movers_.v.size() < n) movers_.v.resize(n);
    float* const old_phi = old_phi_.v.data();
    std::int8_t* const move = move_.v.data();
    std::uint32_t* const movers = movers_.v.data();

    // 1. New zero-layer values (all Δ were computed from the old state, so this is Jacobi), and
    //    each chunk's leaving edits (movers_ holds them at the chunk's offset until step 2 is done).
    //    With the rule, also each chunk's candidates for its pinned test (near_edge_ at the chunk's
    //    offset): a point that leaves ends a mover (beyond ±0.5) or clamped to ±0.5 by step 2 - as
    //    ±2, blocked, stuck without the test (thin_front.cpp), or as ±3, with no L∓1 neighbour on
    //    the other side to hand the front to - so only the points that stay are candidates.
    std::vector<std::size_t> n_leaving((n + detail::kChunk - 1) / detail::kChunk);
    std::vector<std::size_t> n_near(rule != nullptr ? n_leaving.size() : 0);
    if (rule != nullptr && near_edge_.v.size() < n) near_edge_.v.resize(n);
    PointIndex* const near = near_edge_.v.data();
    detail::for_chunks(n, [&](std::size_t b, std::size_t e) {
        const std::size_t c = b / detail::kChunk;
        n_leaving[c] = rule != nullptr ? move_values<true>(edits.data(), b, e, phi, old_phi, move, movers, near, &n_near[c])
                                       : move_values<false>(edits.data(), b, e, phi, old_phi, move, movers, nullptr, nullptr);
    });
    // 2. Classify the leaving edits (reads only). A point whose neighbour leaves the other way
    //    stays, clamped to ±0.5, so the front never jumps over a lattice edge.
    detail::for_chunks(n, [&](std::size_t b, std::size_t) {
        classify_moves(edits.data(), std::span<const std::uint32_t>(movers + b, n_leaving[b / detail::kChunk]), phi, status,
                       lat, decoder, move);
    });
    // The movers, in edit order: each chunk's leaving edits but the blocked ones (compacted in
    // place: a mover is written at or before where it was read).
    std::size_t n_movers = 0;
    std::vector<StuckPoint> blocked;
    for (std::size_t c = 0; c < n_leaving.size(); ++c)
        for (std::size_t j = 0; j < n_leaving[c]; ++j) {
            const std::uint32_t k = movers[c * detail::kChunk + j];
            const std::int8_t m = move[k];
            if (m >= 2 || m <= -2) [[unlikely]] {
                phi[edits[k].point] = m > 0 ? 0.5f : -0.5f;
                move[k] = 0;
                if (rule != nullptr && (m == 2 || m == -2)) blocked.push_back({edits[k].point, m > 0 ? std::int8_t{-1} : std::int8_t{1}});
            }
            movers[n_movers] = k;
            n_movers += move[k] != 0 ? 1 : 0;
        }
    // The thin-front rule's entries, from the zero layer's final new values (the candidates of its
    // pinned test compacted in place, in edit order).
    std::size_t n_near_all = 0;
    for (std::size_t c = 0; c < n_near.size(); ++c) {
        const PointIndex* const from = near + c * detail::kChunk;
        if (from != near + n_near_all) std::copy(from, from + n_near[c], near + n_near_all);  // to before it
        n_near_all += n_near[c];
    }
    const std::vector<FrontEntry> entries =
        rule != nullptr ? rule_entries(*rule, std::span<const PointIndex>(near, n_near_all), blocked, edits, old_phi)
                        : std::vector<FrontEntry>{};

    // 3. The front passes to the neighbours on the other side: an L∓1 neighbour of a leaving point
    //    enters the zero layer (marked at once, so it enters once) with the value implied by the
    //    zero layer's new values: over its zero-layer neighbours (not those entering it here, whose
    //    status is no longer 0, so the order of entering changes no value), φ + 1 or φ − 1.
    detail::reserve_growing(region, 6 * n_movers + entries.size() + n);
    region.resize(6 * n_movers + entries.size() + n);
    RegionPoint* const out = region.data();
    std::size_t n_out = 0;
    const detail::Neighbors6 around(lat, decoder);  // its prefetch only
    for (std::size_t m = 0; m < n_movers; ++m) {
        if (m + detail::kAhead < n_movers) around.prefetch(phi, status, edits[movers[m + detail::kAhead]].point);
        const std::size_t k = movers[m];
        const std::int8_t from = move[k] > 0 ? std::int8_t{-1} : std::int8_t{1};
        for_each_neighbor6(lat, decoder, edits[k].point, [&](PointIndex q) __attribute__((always_inline)) {
            const std::int8_t s = status[q];
            const bool enters = s == from;
            out[n_out] = {q, s, phi[q]};
            status[q] = enters ? detail::kPendZero : s;
            n_out += enters ? 1 : 0;
        });
    }
    const auto is_zero = [](std::int8_t s) { return s == 0; };
    for (std::size_t r = 0; r < n_out; ++r) {
        if (r + detail::kAhead < n_out) around.prefetch(phi, status, out[r + detail::kAhead].point);
        const PointIndex q = out[r].point;
        phi[q] = detail::layer_value(phi_, status_, q, decoder.coord(q), out[r].old_status > 0, is_zero);
    }
    n_out += enter_zero_layer(entries, out + n_out);
    // Then the edited points: a point that keeps its layer and its bits changes nothing and is no
    // seed of the region; the others are marked pending on their side (status 0 before).
    constexpr std::int8_t pending[3] = {kPendNeg, kPendZero, kPendPos};
    for (std::size_t k = 0; k < n; ++k) {
        const PointIndex i = edits[k].point;
        const std::int8_t m = move[k];
        const bool seed = m != 0 || std::bit_cast<std::uint32_t>(phi[i]) != std::bit_cast<std::uint32_t>(old_phi[k]);
        out[n_out] = {i, 0, old_phi[k]};
        status[i] = seed ? pending[m + 1] : std::int8_t{0};
        n_out += seed ? 1 : 0;
    }
    region.resize(n_out);
}

void SparseField::relist(PointList& zero) {
    std::vector<PointList>& levels = level_claims_.v;
    for (int k = 1; k <= layers_; ++k) {
        lists_[static_cast<std::size_t>(layers_ + k)].swap(levels[2 * static_cast<std::size_t>(k - 1)]);
        lists_[static_cast<std::size_t>(layers_ - k)].swap(levels[2 * static_cast<std::size_t>(k - 1) + 1]);
    }
    lists_[static_cast<std::size_t>(layers_)].swap(zero);
    zero_reordered_ = 0;  // the zero layer came sorted
    // The slots are written when next needed (ensure_slots): a growing front rebuilds its lists
    // step after step and needs none of them.
    slots_stale_ = true;
}

void SparseField::collect_ball(PointIndex seed, std::vector<RegionPoint>& region) {
    const Vec3i c = lattice().coord(seed);
    const Vec3i d = lattice().dims();
    const int r = layers_;
    const bool interior = c.x >= r && c.y >= r && c.z >= r && c.x < d.x - r && c.y < d.y - r && c.z < d.z - r;
    const auto sy = static_cast<std::int64_t>(lattice().stride_y());
    const auto sz = static_cast<std::int64_t>(lattice().stride_z());
    for (const Vec3i o : ball_) {
        if (!interior && !lattice().contains(c + o)) continue;
        const std::int64_t q = static_cast<std::int64_t>(seed) + o.x + o.y * sy + o.z * sz;
        mark_pending(static_cast<PointIndex>(q), region);
    }
}

SparseField::PointList& SparseField::collect_band(std::vector<RegionPoint>& region) {
    // Room for the band and as many far points reached as the outermost lists hold (so the
    // region grows without copying itself on most steps); written through a buffer sized first.
    const std::size_t marked = region.size();
    detail::reserve_growing(region, marked + band_size() + layer(-layers_).size() + layer(layers_).size());
    region.resize(marked + band_size());
    // The new zero layer: every band point now pending on it. A point enters it only from L0 or
    // L±1 (marked kPendZero by move_zero_layer, or a zero-layer point it left unchanged).
    PointList& zero = zero_next_.v;  // kept: after a relist it holds the old zero list's memory
    detail::reserve_growing(zero, layer(-1).size() + layer(0).size() + layer(1).size());
    zero.resize(layer(-1).size() + layer(0).size() + layer(1).size());
    // Marking changes statuses, never the lists, so iterating the lists here is safe; every list
    // point is visited once. Without a branch on its status (a moving front's are unpredictable):
    // each point writes its region entry and its zero-layer entry and counts each or not, all three
    // from one table entry by its status: the low byte the status it takes (a temporary status,
    // already marked, stays as it is), bit 8 whether it joins the region (not yet marked), bit 9
    // whether it is on the new zero layer.
    static const std::array<std::uint16_t, 256> mark = [] {
        std::array<std::uint16_t, 256> t{};
        for (int b = 0; b < 256; ++b) {
            const auto st = static_cast<std::int8_t>(b);
            const auto after = static_cast<std::uint8_t>(is_temp(st) ? st : detail::pending_of(st));
            const unsigned joins = is_temp(st) ? 0u : 1u, zero = st == 0 || st == kPendZero ? 1u : 0u;
            t[static_cast<std::size_t>(b)] = static_cast<std::uint16_t>(after | joins << 8 | zero << 9);
        }
        return t;
    }();
    const float* const phi = phi_.values().data();  // raw: a status store could alias the members
    std::int8_t* const status = status_.values().data();
    RegionPoint* const out = region.data();
    PointIndex* const z = zero.data();
    std::size_t n_out = marked, n_zero = 0;
    for (const auto& list : lists_) {
        const PointIndex* const points = list.data();
        const std::size_t size = list.size();
        for (std::size_t n = 0; n < size; ++n) {
            if (n + detail::kAhead < size) {  // a list's points are scattered: fetch ahead
                __builtin_prefetch(status + points[n + detail::kAhead], 1);
                __builtin_prefetch(phi + points[n + detail::kAhead], 0);
            }
            const PointIndex i = points[n];
            const std::int8_t s = status[i];
            const unsigned m = mark[static_cast<std::uint8_t>(s)];
            out[n_out] = {i, s, phi[i]};
            n_out += (m >> 8) & 1u;
            z[n_zero] = i;
            n_zero += m >> 9;
            status[i] = static_cast<std::int8_t>(m & 0xFFu);
        }
    }
    region.resize(n_out);
    zero.resize(n_zero);
    return zero;
}

ActivitySnapshot SparseField::activity_snapshot(std::uint64_t next_speed_serial) const {
    ActivitySnapshot s = activity_.snapshot(next_speed_serial);
    s.clock = steps_;
    return s;
}

void SparseField::restore_activity(const ActivitySnapshot& snapshot) {
    activity_.restore(snapshot, lattice());
    steps_ = snapshot.clock;
}

}  // namespace liveset
