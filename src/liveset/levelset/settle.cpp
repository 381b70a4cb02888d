// Settling a repair region (see sparse_field.hpp for the scheme): each point's final status, X and
// the sign changes (finish), and the moves of the points whose layer changed between the lists.
#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "liveset/levelset/band_detail.hpp"
#include "liveset/levelset/sparse_field.hpp"

namespace liveset {

namespace {

using detail::kPendNeg;
using detail::kPendPos;
using detail::kPendZero;
using detail::same_bits;

// finish's pass over region[b, e): each point settled (a pending one is far: it left the band),
// its index stored and counted if its layer or φ's bits changed, the move recorded (kMoves) if its
// layer did, the point kept in `signs` if its sign did; returns how many changed and how many moved.
// A free function so that every pointer it reads is a local: a status store, through a char type,
// would make a closure's members reload on every point. Counts without branching on a change
// (unpredictable).
template <bool kMoves, class Record, class Move>
std::pair<std::size_t, std::size_t> settle_region(const Record* points, std::size_t b, std::size_t e, float* phi,
                                                  std::int8_t* status, std::int8_t far_out, PointIndex* changed,
                                                  Move* moved, std::vector<PointIndex>& signs) {
    const float far = static_cast<float>(far_out);
    const auto far_in = static_cast<std::int8_t>(-far_out);
    std::size_t n_changed = 0, n_moved = 0;
    for (std::size_t n = b; n < e; ++n) {
        if (n + detail::kAhead < e) {  // the region's points are scattered: fetch ahead
            __builtin_prefetch(status + points[n + detail::kAhead].point, 1);
            __builtin_prefetch(phi + points[n + detail::kAhead].point, 0);
        }
        const Record r = points[n];
        const PointIndex i = r.point;
        std::int8_t s = status[i];
        float v = phi[i];
        // Only a pending status is written: the sweeps left every other one final, and a store
        // to a line another chunk's points share would make the cores fight over it.
        if (s == kPendZero) {
            s = 0;
            status[i] = s;
        } else if (s == kPendPos || s == kPendNeg) {  // left the band
            s = s == kPendPos ? far_out : far_in;
            v = s == far_out ? far : -far;
            status[i] = s;
            phi[i] = v;
        }
        const std::size_t layer_changed = s != r.old_status ? 1 : 0;
        if constexpr (kMoves) moved[n_moved] = {n, s};
        n_moved += layer_changed;
        changed[n_changed] = i;
        n_changed += layer_changed | (same_bits(v, r.old_phi) ? 0u : 1u);
        if ((v < 0.0f) != (r.old_phi < 0.0f)) signs.push_back(i);
    }
    return {n_changed, n_moved};
}

}  // namespace

// Moves the points whose layer changed between the lists: every removal, then every addition, each
// in region order. The moves are first bucketed by list (a stable counting sort), so that each
// list walks only its own; a list's operations touch only its own points' slots, so each list is
// one task once there are many moves; the lists come out the same on any thread count.
void SparseField::move_between_lists(std::span<const RegionPoint> region, std::span<const ListMove> moves) {
    ensure_slots();  // list_add and list_remove use them
    const int lists = 2 * layers_ + 1;
    const auto list_of = [&](int layer) { return layer >= -layers_ && layer <= layers_ ? layer + layers_ : -1; };
    // begin[l] .. begin[l + 1]: list l's points; counted one slot up, then summed.
    std::array<std::size_t, 2 * kMaxLayers + 2> out_begin{}, in_begin{};
    for (const ListMove& m : moves) {
        const int from = list_of(region[m.region_index].old_status), to = list_of(m.layer);
        if (from >= 0) ++out_begin[static_cast<std::size_t>(from) + 1];
        if (to >= 0) ++in_begin[static_cast<std::size_t>(to) + 1];
    }
    for (int l = 0; l < lists; ++l) {
        out_begin[static_cast<std::size_t>(l) + 1] += out_begin[static_cast<std::size_t>(l)];
        in_begin[static_cast<std::size_t>(l) + 1] += in_begin[static_cast<std::size_t>(l)];
    }
    PointList& out = moved_out_.v;
    PointList& in = moved_in_.v;
    out.resize(out_begin[static_cast<std::size_t>(lists)]);
    in.resize(in_begin[static_cast<std::size_t>(lists)]);
    {
        auto out_at = out_begin, in_at = in_begin;
        for (const ListMove& m : moves) {
            const RegionPoint& r = region[m.region_index];
            const int from = list_of(r.old_status), to = list_of(m.layer);
            if (from >= 0) out[out_at[static_cast<std::size_t>(from)]++] = r.point;
            if (to >= 0) in[in_at[static_cast<std::size_t>(to)]++] = r.point;
        }
    }
    const bool parallel = moves.size() >= detail::kParallelMin;
    // A point leaves its old list before it enters its new one (both touch its slot).
    // The points are scattered: each loop fetches the slots it will touch a few points ahead (a
    // removal also rewrites the slot of its list's last point, and the lists shrink from the back).
    const std::uint32_t* const slot = slot_.values().data();
    detail::for_each_list(lists, parallel, [&](std::size_t l) {
        const PointList& list = lists_[l];
        const std::size_t end = out_begin[l + 1];
        for (std::size_t n = out_begin[l]; n < end; ++n) {
            if (n + detail::kAhead < end) __builtin_prefetch(slot + out[n + detail::kAhead], 1);
            if (list.size() > detail::kAhead) __builtin_prefetch(slot + list[list.size() - 1 - detail::kAhead], 1);
            list_remove(out[n], static_cast<int>(l) - layers_);
        }
    });
    detail::for_each_list(lists, parallel, [&](std::size_t l) {
        const std::size_t end = in_begin[l + 1];
        for (std::size_t n = in_begin[l]; n < end; ++n) {
            if (n + detail::kAhead < end) __builtin_prefetch(slot + in[n + detail::kAhead], 1);
            list_add(in[n], static_cast<int>(l) - layers_);
        }
    });
}

// Settles every region point (a pending one is far), in parallel over fixed chunks; then moves the
// points whose layer changed between the lists (move_between_lists), unless the caller rebuilds
// them (relist). The change report and the sign changes come in the region's order, whatever the
// thread count.
ChangedPoints SparseField::finish(std::span<const RegionPoint> region, bool rebuilding_lists, std::size_t* layer_changes) {
    struct Part {
        std::vector<PointIndex> changed, signs;
        std::vector<ListMove> moved;  // the points whose layer changed (when the lists are moved)
        std::size_t n_moved = 0;
    };
    const bool record_moves = !rebuilding_lists;
    const std::int8_t far_out = far_outside();
    float* const phi = phi_.values().data();  // raw: see sweep_whole_band
    std::int8_t* const status = status_.values().data();
    const RegionPoint* const points = region.data();
    auto parts = detail::ordered_chunks<Part>(region.size(), [=](std::size_t b, std::size_t e, Part& out) {
        out.changed.resize(e - b);                   // most region points change: a store and a count each
        if (record_moves) out.moved.resize(e - b);  // and many move (unpredictably): the same
        const auto [n_changed, n_moved] =
            record_moves ? settle_region<true>(points, b, e, phi, status, far_out, out.changed.data(), out.moved.data(), out.signs)
                         : settle_region<false>(points, b, e, phi, status, far_out, out.changed.data(), out.moved.data(), out.signs);
        out.changed.resize(n_changed);
        if (record_moves) out.moved.resize(n_moved);
        out.n_moved = n_moved;
    });
    if (layer_changes != nullptr) {
        *layer_changes = 0;
        for (const Part& p : parts) *layer_changes += p.n_moved;
    }
    if (record_moves) {
        std::vector<ListMove> moved;
        detail::join_parts(parts, &Part::moved, moved);
        move_between_lists(region, moved);
    }
    ChangedPoints changed;
    detail::join_parts(parts, &Part::changed, changed.points);
    detail::join_parts(parts, &Part::signs, changed.sign_changes.emplace());
    return changed;
}

}  // namespace liveset
