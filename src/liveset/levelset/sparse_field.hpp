// SparseField: Whitaker's sparse-field level set (1998) with local modification.
//
// φ < 0 inside. The band is the zero layer L0 (φ in [-0.5, 0.5]) and layers L±1..L±N (φ in
// [k-0.5, k+0.5]); points beyond are "far" with φ clamped to ±(N+1). A status lattice holds each
// point's layer (±(N+1) when far) and one list per layer holds the band points.
//
// Every update has the same shape:
//   1. zero-layer values change by Δ (|Δ| ≤ 0.5, the step bound);
//   2. points leaving L0 (φ beyond ±0.5) pass the front to their neighbours in L∓1, which enter L0;
//      two neighbours moving in opposite directions both stay (clamped to ±0.5), so no order matters;
//      in a global step with StepOptions::thin_fronts, an L±1 point beside a zero-layer point that
//      cannot pass the front on (FrontRule) enters L0 where its own rate brings it into L0's range;
//   3. the outer layers are recomputed from the new zero layer, layer by layer (L±k from L±(k-1):
//      φ = min/max over neighbours of φ ± 1, layer_value.hpp), as Jacobi sweeps over a region.
// The layers are a pure function of the zero layer, its values and the points' signs, and each
// point depends only on its neighbours one level further in. So a *global* update (region = whole
// band) and a *local* one (re-layering outwards from what changed, level by level, cost
// proportional to the points touched) give bitwise-identical φ and status, whatever the thread
// count. A global step can be either (StepMode); the incremental one can also let converged
// stretches of front sleep (StepOptions::sleep_after, activity.hpp).
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <optional>
#include <vector>

#include "liveset/grid/grid.hpp"
#include "liveset/grid/index_decoder.hpp"
#include "liveset/grid/uninit_allocator.hpp"
#include "liveset/levelset/activity.hpp"
#include "liveset/levelset/plane_split.hpp"
#include "liveset/levelset/speed.hpp"

namespace liveset {

// X in the paper: lattice points whose φ or status changed in one update (the mesher's input).
struct ChangedPoints {
    std::vector<PointIndex> points;
    // The points of `points` whose sign of φ (φ < 0) changed, where the producer knows them (every
    // SparseField update reports them); a mesher then reads φ only there. Unset for a set
    // assembled elsewhere (a whole-state difference, a union kept by a caller), where a mesher
    // must check the sign of every point.
    std::optional<std::vector<PointIndex>> sign_changes;
    bool empty() const { return points.empty(); }
    std::size_t size() const { return points.size(); }
};

// A requested change of φ at a zero-layer point.
struct ZeroLayerEdit {
    PointIndex point;
    float delta;
};

enum class RepairScope {
    kLocal,   // repair only around the edited points
    kGlobal,  // recompute the whole band (what a global update does)
};

// How a global step repairs the band (docs/ARCHITECTURE.md, "Incremental step").
enum class StepMode {
    kFullBand,     // the reference: re-layers the whole band every step
    kIncremental,  // re-layers outwards from what moved, or the whole band when most of a small
                   // front moves (same bits either way); can let stretches sleep
};

struct StepOptions {
    float cfl = 0.5f;        // largest |Δφ| of one step (at most 0.5, the sparse-field step bound)
    float max_dt = 1.0e9f;   // optional cap on the time step
    // The full-band reference by default; kIncremental gives its bits and costs what moves, or
    // when most of the front moves, the whole band as the cheaper of two exact repairs (the
    // reference's push sweep where many points change layer, a growing segmentation; changes of
    // layer and one value pass over the lists where few do, a curvature flow: 0.75-0.85x the
    // sweep's time per step on the box, docs/BENCHMARKS.md, session 45).
    StepMode mode = StepMode::kFullBand;
    // Sleeping (needs kIncremental; docs/ARCHITECTURE.md, "Activity"): a stretch of front where no
    // point changed sign within 2-3 points for `sleep_after` steps sleeps - its zero-layer points
    // are neither evaluated nor moved - until a sign change or an edit near it, or a new speed,
    // wakes it. 0 (the default) never sleeps: kIncremental is then the full-band step bit for bit.
    // `liveset segment` uses 20 (segment_step(), segmentation.hpp). At most 1 000 000.
    int sleep_after = 0;
    // kIncremental only: when at least 3/5 of a zero layer of at most this many points moves in a
    // step, the band is re-layered whole (the push sweep, its lists rebuilt from the sweep's
    // levels) instead of outwards from the changes: the same bits (local ≡ global), and cheaper
    // there. docs/BENCHMARKS.md, session 42: on BrainWeb the fronts of 60 000-100 000 points, 70-78 %
    // of them moving, took 0.68-0.73x the time whole on one thread, 0.89x on two; no size or
    // fraction beyond these paid (from 100 000 points on two threads, where sleeping stretches leave
    // fewer points moving: no cap up to 1.18x slower, 1/2 up to 1.17x, 11/20 up to 1.65x). Sessions
    // 25 and 36 had set 30 000 and 60 000 with 3/4. 0: always propagate. At most 1 000 000 000.
    std::size_t dense_front_max = 150'000;
    // A step over a band of fewer points runs on the calling thread alone (bitwise the same
    // result): its loops are too short to pay for waking another thread, which costs tens of
    // microseconds per parallel loop on a virtual machine (docs/BENCHMARKS.md, session 31: on the
    // 2-core VM two threads were 1.3-1.6x slower than one below 30 000 front points; session 35:
    // with today's passes they break even at about 90 000 band points, 20 000 on BrainWeb's
    // front). Such a step also splits no level for two tasks (session 43), so the order of the
    // lists and of X follows this option as it follows dense_front_max (the same φ, statuses and X
    // as a set; the same order on any thread count). 0: always use the threads there are. At most
    // 1 000 000 000.
    std::size_t parallel_band_min = 100'000;
    // The thin-front rule (docs/ARCHITECTURE.md, "Thin fronts"; FrontRule): a front carries into
    // structures one or two voxels across, which Whitaker's scheme cannot enter. Off here (the
    // paper's sparse field, as the phantom demo steps: on the cortex phantom the rule carries the
    // front around the weak spots along their partial-volume rims, leaving a handle and a pocket
    // where a perforation was, docs/BENCHMARKS.md session 71); on in segment_step(), the step
    // `liveset segment` takes by default (session 72).
    bool thin_fronts = false;
};

// Throws std::invalid_argument with a one-line message on an option out of range.
void validate(const StepOptions& options);

// One point's complete level-set state (φ and status), as recorded for undo and redo.
struct PointState {
    PointIndex point;
    float phi;
    std::int8_t status;
};

struct StepResult {
    double dt = 0.0;               // time step taken
    std::size_t zero_layer = 0;    // zero-layer size before the step
    std::size_t awake = 0;         // zero-layer points evaluated (all of them unless sleeping)
    bool whole_band = false;       // the repair re-layered the whole band (kFullBand; a dense kIncremental step)
    bool value_pass = false;       // ... by changes of layer and a value pass (a dense step, few points changing layer)
    ChangedPoints changed;         // points whose φ or status changed, and those whose sign changed
};

class SparseField {
public:
    static constexpr int kMaxLayers = 8;

    // layers: N ≥ 1 (N = 2 gives L0, L±1, L±2). Throws std::invalid_argument otherwise.
    explicit SparseField(const Lattice& lattice, int layers = 2);

    // --- initialisation (each replaces the whole state) -------------------------------------
    // From a signed distance (index-space position -> distance in voxels, negative inside).
    void init_from_sdf(const std::function<double(Vec3d)>& sdf);
    // The same, evaluating `sdf` only in the box [lo, hi] (inclusive, clipped to the lattice):
    // it must be ≥ N + 1 at every lattice point outside the box (as for unite_in_box). Same bits
    // as the whole-lattice form; cost grows with the box, plus a fill of φ and the statuses.
    void init_from_sdf(const std::function<double(Vec3d)>& sdf, Vec3i lo, Vec3i hi);
    // From a binary mask on the same lattice dimensions (non-zero = inside).
    void init_from_mask(const Grid<std::uint8_t>& mask);

    // --- state ----------------------------------------------------------------------------
    const Lattice& lattice() const { return phi_.lattice(); }
    int layers() const { return layers_; }
    const Grid<float>& phi() const { return phi_; }
    const Grid<std::int8_t>& status() const { return status_; }
    std::int8_t far_outside() const { return static_cast<std::int8_t>(layers_ + 1); }
    std::int8_t far_inside() const { return static_cast<std::int8_t>(-(layers_ + 1)); }
    // Points of layer k, k in [-N, N]; order is unspecified but deterministic.
    std::span<const PointIndex> layer(int k) const;
    std::span<const PointIndex> zero_layer() const { return layer(0); }
    std::size_t band_size() const;
    bool in_band(PointIndex i) const { return status_[i] >= -layers_ && status_[i] <= layers_; }

    // The sleeping rule's memory (the step clock and the wake stamps; activity.hpp), to save with
    // φ and the statuses so that a continued run takes exactly the steps the uninterrupted one
    // would. `next_speed_serial`: the serial of the speed the next step will use (0: not built).
    ActivitySnapshot activity_snapshot(std::uint64_t next_speed_serial) const;
    // After φ and the statuses were restored. Throws std::invalid_argument for another lattice.
    void restore_activity(const ActivitySnapshot& snapshot);

    // --- updates ----------------------------------------------------------------------------
    // One global step of ∂φ/∂t = |∇φ| F (φ in index units, |∇φ| per finest voxel: per mm times the
    // smallest voxel size h_min, so a front moves alike in mm along every axis; κ in a curvature part
    // per mm) with a CFL time step (|Δφ| ≤ cfl and the parabolic bound dt ≤ h_min/(4·curvature
    // weight), the explicit scheme's stability limit; at 1 mm all of it in index units), multithreaded over the
    // zero layer (a band below options.parallel_band_min on the calling thread alone). Both modes
    // give the same φ, statuses and change report (as a set); kIncremental costs what moved (the
    // band when most of a small front moves), kFullBand the band.
    StepResult step(const Speed& speed, const StepOptions& options = {});
    // The Δφ a global step would apply (one edit per zero-layer point) and its time step. With
    // StepOptions::thin_fronts, step() also applies the thin-front rule in its repair (FrontRule),
    // which apply_edits never does: these edits applied are then not that step.
    std::vector<ZeroLayerEdit> compute_step(const Speed& speed, const StepOptions& options, double* dt) const;

    // Applies edits to zero-layer points (duplicates are summed; each Δ is clamped to ±0.5) and
    // repairs the band. Throws std::invalid_argument, before changing anything, if a point is not
    // on the zero layer or a Δ is not finite.
    ChangedPoints apply_edits(std::span<const ZeroLayerEdit> edits, RepairScope scope = RepairScope::kLocal);
    // Local edit of the zero-layer points inside the box [lo, hi] (inclusive, clipped to the
    // lattice): delta(p, φ(p)) gives each point's Δ. Cost grows with the box, not the band.
    ChangedPoints apply_in_box(Vec3i lo, Vec3i hi, const std::function<float(Vec3i, float)>& delta);
    // The union with a shape — init_from_sdf(min(φ, sdf)) — computed only where it can differ:
    // `sdf` (index space, negative inside) must be ≥ N + 1 outside the box [lo, hi] (clipped to
    // the lattice). Re-layers the Manhattan N-ball of every changed value; cost grows with the box.
    // Same bits as the whole-lattice re-initialisation wherever that one keeps the band's values
    // (it also re-snaps a non-zero-layer point whose φ is exactly ±0.5 anywhere; this does not).
    // Throws std::invalid_argument, before changing anything, where `sdf` is not finite.
    ChangedPoints unite_in_box(Vec3i lo, Vec3i hi, const std::function<double(Vec3d)>& sdf);

    // Writes back φ and status at the given points and moves them to the lists of their restored
    // layers (undo / redo). The states must be ones recorded earlier for *every* point that changed
    // since (e.g. the first-touched old state of each point of every X of an action): together
    // with the untouched points they then form that earlier, valid state again, bit for bit (the
    // lists hold the same points; only their order may differ, which no update depends on).
    // Returns the points whose φ (bitwise) or status changed, for the mesher. Throws
    // std::invalid_argument, before changing anything, on a point outside the lattice, a status
    // outside [-(N+1), N+1] or a non-finite φ.
    ChangedPoints restore(std::span<const PointState> states);

    // Wall time of the last update's level-set work (step, apply_edits, apply_in_box or restore),
    // for the viewer's per-frame breakdown; not part of the state.
    double last_update_ms() const { return last_update_ms_; }

private:
    // A layer list or a level's claims: sized first, then written entry by entry (no zero fill).
    using PointList = UninitVector<PointIndex>;
    struct RegionPoint {
        RegionPoint() {}  // left unset: a buffer of them is sized first and each entry written once
        RegionPoint(PointIndex i, std::int8_t status, float phi) : point(i), old_status(status), old_phi(phi) {}
        PointIndex point;
        std::int8_t old_status;
        float old_phi;
    };

    void evaluate_sdf(const std::function<double(Vec3d)>& sdf, Vec3i lo, Vec3i hi);  // φ, far outside the box
    void clear_lists();                     // no layer lists, no slots, everything awake (a new front)
    // The statuses, lists and band from φ set in [lo, hi] (far outside). `steep`: φ may change sign
    // between two points beyond ±0.5 (a function steeper than a distance), which are then pulled
    // onto the zero layer; false where φ cannot (init_from_mask: both sides of a sign change are ±0.5).
    void band_from_phi(Vec3i lo, Vec3i hi, bool steep = true);
    std::vector<double> zero_rates(const Speed& speed) const;  // |∇φ|F at each zero-layer point
    double time_step(std::span<const double> rate, const Speed& speed, const StepOptions& options) const;
    double parabolic_factor() const;  // the curvature's stability factor 1/h_min from the voxel sizes (time_step)
    StepResult step_full_band(const Speed& speed, const StepOptions& options);
    StepResult step_incremental(const Speed& speed, const StepOptions& options);  // incremental_step.cpp
    // The thin-front rule of a global step with StepOptions::thin_fronts (docs/ARCHITECTURE.md,
    // "Thin fronts"; thin_front.cpp): where a zero-layer point that moved cannot pass the front
    // on - it is blocked (a neighbour leaves the other way), or pinned (its new value within 0.25
    // of its side's edge and no neighbour half a voxel or more beyond it: its upwind |∇φ| has
    // collapsed, as in a structure at most two voxels across) - its L±1 neighbours on the other
    // side are stepped by their own rate (clamped to ±cfl), from the zero layer's new values, and
    // enter the zero layer where that brings them into its range on their own side. Local edits
    // take no such rule (they have no speed).
    struct FrontRule {
        const Speed& speed;
        double dt;
        double cfl;
    };
    struct FrontEntry {
        PointIndex point;
        float phi;  // the new value
    };
    struct StuckPoint {
        PointIndex point;
        std::int8_t other;  // the status of its L±1 neighbours on the other side
    };
    // The entries the rule gives the points ahead `ahead` (points_ahead), in their (lattice) order.
    std::vector<FrontEntry> front_entries(const FrontRule& rule, std::span<const PointIndex> ahead) const;
    // The L±1 neighbours on the other side of a repair's stuck points - `blocked` (from step 2:
    // those with an L∓1 neighbour on the other side, the only ones that can hand the front over)
    // and the pinned ones among `near` (the edits whose value changed and stayed in the zero
    // layer, now within 0.25 of their side's edge: step 1) - towards which the propagation part
    // moves the front, once each, in lattice order.
    std::vector<PointIndex> points_ahead(const FrontRule& rule, std::span<const PointIndex> near,
                                         std::span<const StuckPoint> blocked) const;
    // The rule's entries for such a repair: reads only, except that a speed that throws leaves
    // every edit's value as it was (`old_phi`).
    std::vector<FrontEntry> rule_entries(const FrontRule& rule, std::span<const PointIndex> near, std::span<const StuckPoint> blocked,
                                         std::span<const ZeroLayerEdit> edits, const float* old_phi);
    ChangedPoints commit(std::span<const ZeroLayerEdit> edits, RepairScope scope,
                         const FrontRule* rule = nullptr);  // timed repair_band
    ChangedPoints repair_band(std::span<const ZeroLayerEdit> edits, RepairScope scope, const FrontRule* rule = nullptr);
    // The repair's first steps: the zero layer's new values, the front handed over to the
    // neighbours entering it (with `rule`, also the thin-front rule's entries), and the changed
    // points marked pending, into the (empty) region.
    void move_zero_layer(std::span<const ZeroLayerEdit> edits, std::vector<RegionPoint>& region, const FrontRule* rule);
    // Takes the rule's entries that no hand-over took into the zero layer (pending), recording each
    // at out[0], out[1], ...; returns how many.
    std::size_t enter_zero_layer(std::span<const FrontEntry> entries, RegionPoint* out);
    // Re-layers level by level from the pending points in `region` (the zero layer's changes),
    // re-evaluating only what a change at the level below can reach; appends what it marks.
    // `pulled` (the dense form): only changes of layer propagate; every other point of each layer
    // takes its value from the level inside it (pass_values), and those whose value changed are
    // appended to `pulled`.
    void relayer_changes(std::vector<RegionPoint>& region, std::vector<PointIndex>* pulled = nullptr);  // relayer.cpp
    void pass_values(int k, std::vector<PointIndex>& pulled);
    // The repair of a step where most of the zero layer moved (step_incremental): the whole band
    // either way, with the same bits; by the dense form of relayer_changes when the last whole-band
    // repair changed the layer of under a tenth of the band (pass_next_), else as repair_band's
    // global repair (the push sweep).
    ChangedPoints repair_dense(std::span<const ZeroLayerEdit> edits, const FrontRule* rule);
    void collect_ball(PointIndex seed, std::vector<RegionPoint>& region);
    // Marks the whole band pending (appending what it marks); returns the new zero layer (held in
    // zero_next_, whose memory a relist swaps with the old zero list's, so none is allocated per step).
    PointList& collect_band(std::vector<RegionPoint>& region);
    void mark_pending(PointIndex i, std::vector<RegionPoint>& region);
    void sweep_layers(std::span<const RegionPoint> region);       // any region (pull)
    // The whole band (push, same bits) from the new zero layer `zero`; appends the
    // far points it reaches to the region. `keep_levels`: each level's claims, split by side, are
    // kept (in the order claimed) in level_claims_, for finish to rebuild the lists from.
    void sweep_whole_band(std::vector<RegionPoint>& region, std::span<const PointIndex> zero, bool keep_levels = false);
    struct ListMove {
        ListMove() {}  // left unset: finish sizes its buffer first and writes each entry it counts
        ListMove(std::size_t index, std::int8_t new_layer) : region_index(static_cast<std::uint32_t>(index)), layer(new_layer) {}
        std::uint32_t region_index;  // a region holds lattice points, fewer than 2^32
        std::int8_t layer;           // the new status
    };
    // The points that changed layer are moved between the lists, unless `rebuilding_lists` (the
    // caller then rebuilds them: relist): no move is recorded. `layer_changes`: where to count
    // those points.
    ChangedPoints finish(std::span<const RegionPoint> region, bool rebuilding_lists = false,
                         std::size_t* layer_changes = nullptr);
    // The lists from the new zero layer (in lattice order) and the levels' claims; every list
    // point's slot is written when next needed (ensure_slots).
    void relist(PointList& zero);
    // Writes every list point's slot if relist left them stale (before list_add / list_remove).
    void ensure_slots();
    void move_between_lists(std::span<const RegionPoint> region, std::span<const ListMove> moves);
    void sort_lists(bool zero_only = false);  // each (or the zero) layer list in ascending point order
    void list_add(PointIndex i, int layer);
    void list_remove(PointIndex i, int layer);

    int layers_;
    Grid<float> phi_;
    Grid<std::int8_t> status_;
    Grid<std::uint32_t> slot_;                 // position of a band point in its layer list, unless stale:
    bool slots_stale_ = false;                  // relist left slot_ to be written (ensure_slots)
    std::vector<PointList> lists_;  // index k + N holds layer k
    std::vector<Vec3i> ball_;                  // offsets within Manhattan distance N
    int steps_since_sort_ = 0;
    // Whether a large level's sources are split for two tasks (plane_split.hpp): not in a step
    // whose band is below StepOptions::parallel_band_min, which runs on the calling thread alone
    // (the split is then two passes over the sources for nothing). Decided by the band's size, so
    // the claims' order, the lists and X are the same on any thread count.
    bool split_levels_ = true;
    // Whether a level of this many sources is split (plane_split.hpp's threshold, in a step that may
    // use two threads).
    bool splits(std::size_t sources) const { return split_levels_ && sources >= detail::kPlaneSplitMin; }
    // Whether the next whole-band repair rebuilds its lists (relist) rather than moving points
    // between them: set by the last one's share of points that changed layer (repair_band).
    bool relist_next_ = true;
    // Whether the next dense repair propagates only changes of layer and passes over the lists for
    // the values (repair_dense): set by the last whole-band repair's share of the band that changed
    // layer. A front growing from seeds changes 10-30 % of its band per step (BrainWeb), where
    // the push sweep costs 0.65-0.9x the dense form; the box under curvature flow 0-10 %, where the
    // dense form costs 0.75-0.85x the sweep (docs/BENCHMARKS.md, session 45).
    bool pass_next_ = false;
    bool few_layer_changes(std::size_t layer_changes) const { return 10 * layer_changes < band_size(); }  // pass_next_'s rule
    std::size_t zero_reordered_ = 0;  // zero-layer list insertions and removals since its last sort
    double last_update_ms_ = 0.0;
    std::int64_t steps_ = 0;                    // global steps taken (the activity's clock)
    FrontActivity activity_;                    // sleeping stretches of front (kIncremental)
    IndexDecoder decoder_;  // division-free index -> coordinate for the hot loops
    // Working memory of one update, kept so that a global step does not allocate (and fault in)
    // band-sized buffers every time; not part of the state, so a copy of the field starts empty.
    template <class T>
    struct Kept {
        T v;
        Kept() = default;
        Kept(const Kept&) {}
        Kept& operator=(const Kept&) { return *this; }
        Kept(Kept&&) noexcept = default;
        Kept& operator=(Kept&&) noexcept = default;
        ~Kept() = default;
    };
    template <class T>
    using Scratch = Kept<std::vector<T>>;
    Scratch<RegionPoint> region_;                  // repair_band's region
    Scratch<float> old_phi_;                       // move_zero_layer's values before the edits
    Scratch<std::int8_t> move_;                    // its moves, one per edit
    Scratch<std::uint32_t> movers_;                // its edits that leave the zero layer
    Scratch<PointIndex> near_edge_;                // with the thin-front rule, its pinned test's candidates
    Kept<PointList> sweep_from_, sweep_next_;  // sweep_whole_band's levels
    Kept<PointList> zero_next_;                // collect_band's new zero layer (relist swaps it in)
    Scratch<PointList> level_claims_;  // its claims per level and side (2(k-1): outside, +1: inside)
    // relayer_changes' claims: [0] the blocks of an ordered loop (the whole level, or the parts
    // below and the seam of a split), [1] the part above's claims until they join the region,
    // [2] its blocks.
    Scratch<RegionPoint> claims_[3];
    Kept<detail::PlaneSplit> split_;               // a large level's sources split for two tasks (plane_split.hpp)
    Kept<PointList> moved_out_, moved_in_;     // move_between_lists' points, bucketed by list
    Kept<PointList> sort_scratch_;             // sort_lists' radix sort
    Scratch<float> pass_value_;                    // pass_values' new values
};

}  // namespace liveset
