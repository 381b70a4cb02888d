// Re-layering a repair region (see sparse_field.hpp for the scheme): the outer layers from the new
// zero layer (the pull for any region, the push for the whole band, change propagation for a local
// update, or changes of layer only with a value pass over the lists for a dense one); settling it
// (finish) is in settle.cpp.
#include <tbb/parallel_for.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "liveset/levelset/band_detail.hpp"
#include "liveset/grid/float_min_max.hpp"
#include "liveset/levelset/sparse_field.hpp"

namespace liveset {

namespace {

using detail::for_each_neighbor6;
using detail::kNoSlot;
using detail::kPendNeg;
using detail::kPendPos;
using detail::kPendZero;
using detail::same_bits;
using detail::parallel_range;

// What a neighbour's status makes of an offer in the push sweep, looked up instead of branched on
// (a band neighbour's status is unpredictable): keep it; keep the min (the same layer, outside) or
// the max (inside); or claim it (pending or far on the offer's side: it takes the offer). Each is
// one clamp of the old value to [lo, hi], which gives std::min's and std::max's bits; lo and hi are
// picked from the source's four values {-inf, +inf, offer up, offer down} by index.
enum SweepValue : std::uint8_t { kMinusInf, kPlusInf, kOfferUp, kOfferDown };
// A far point claimed at level k holds ±(k + kFarMark) until the level is done (settle_claims
// then gives it ±k and its region record): no layer, far or temporary status (|s| <= 9 or >= 100),
// so the claim needs no store of its own in the sweep's loop, which visits six neighbours per source.
constexpr std::int8_t kFarMark = 50;
static_assert(SparseField::kMaxLayers + 1 < kFarMark && kFarMark + SparseField::kMaxLayers < kPendPos);

// One side's rules at level k, a table per field (one byte load each, no unpacking): by status as
// a byte, the status after, the indices of lo and hi, and whether it is claimed (1: joins the next
// level).
struct SweepRule {
    std::array<std::uint8_t, 256> after, lo, hi, claimed;
};
// rules[side] at level k; side 0 for an outside source, 1 for an inside one (level 1's zero layer
// offers both ways).
using SweepRules = std::array<SweepRule, 2>;

SweepRules sweep_rules(int k, std::int8_t far_out, std::int8_t far_in) {
    const auto at = [](std::int8_t s) { return static_cast<std::uint8_t>(s); };
    const auto up = static_cast<std::int8_t>(k), down = static_cast<std::int8_t>(-k);
    SweepRules rules{};
    for (SweepRule& r : rules)
        for (int s = 0; s < 256; ++s) {  // keep: the status and the value as they are
            const auto b = static_cast<std::size_t>(s);
            r.after[b] = static_cast<std::uint8_t>(s);
            r.lo[b] = kMinusInf;
            r.hi[b] = kPlusInf;
            r.claimed[b] = 0;
        }
    const auto set = [&](int side, std::int8_t s, std::int8_t after, SweepValue lo, SweepValue hi, std::uint8_t claimed) {
        SweepRule& r = rules[static_cast<std::size_t>(side)];
        r.after[at(s)] = at(after);
        r.lo[at(s)] = lo;
        r.hi[at(s)] = hi;
        r.claimed[at(s)] = claimed;
    };
    const auto up_far = static_cast<std::int8_t>(k + kFarMark), down_far = static_cast<std::int8_t>(-k - kFarMark);
    for (int side = 0; side < 2; ++side) {
        if (side == 0 || k == 1) {
            set(side, up, up, kMinusInf, kOfferUp, 0);              // min
            set(side, up_far, up_far, kMinusInf, kOfferUp, 0);      // min (a far point claimed here)
            set(side, kPendPos, up, kOfferUp, kOfferUp, 1);         // claim
            set(side, far_out, up_far, kOfferUp, kOfferUp, 1);      // claim a far point
        }
        if (side == 1 || k == 1) {
            set(side, down, down, kOfferDown, kPlusInf, 0);  // max
            set(side, down_far, down_far, kOfferDown, kPlusInf, 0);
            set(side, kPendNeg, down, kOfferDown, kOfferDown, 1);
            set(side, far_in, down_far, kOfferDown, kOfferDown, 1);
        }
    }
    return rules;
}

// What a change's neighbour of each status becomes when level k's claim reaches it: its pending
// code if it is claimed (not temporary, in layer ±k or beyond, and for k > 1 on the change's
// side), else itself. rules[side][status as a byte], side 1 for a change outside (status > 0).
// Built once for every k and number of layers (a local edit of a few points must not pay for it).
using ClaimRules = std::array<std::array<std::int8_t, 256>, 2>;

const ClaimRules& claim_rules(int k, int layers) {
    constexpr int kMax = SparseField::kMaxLayers;
    static const std::vector<ClaimRules> all = [] {
        std::vector<ClaimRules> tables(static_cast<std::size_t>(kMax * kMax));
        for (int n = 1; n <= kMax; ++n)
            for (int level = 1; level <= n; ++level)
                for (int side = 0; side < 2; ++side)
                    for (int b = 0; b < 256; ++b) {
                        const auto s = static_cast<std::int8_t>(b);
                        const bool claimed = !detail::is_temp(s) && std::abs(s) >= level && std::abs(s) <= n + 1 &&
                                             (level == 1 || (s > 0) == (side == 1));
                        tables[static_cast<std::size_t>((n - 1) * kMax + level - 1)][static_cast<std::size_t>(side)]
                              [static_cast<std::size_t>(b)] = claimed ? detail::pending_of(s) : s;
                    }
        return tables;
    }();
    return all[static_cast<std::size_t>((layers - 1) * kMax + k - 1)];
}

// Which statuses a level-k point on one side takes its value from: layer ±(k-1) (at level 1 the
// zero layer, pending or not), as a table by status byte, looked up instead of compared.
struct InnerStatuses {
    std::array<std::uint8_t, 256> outside{}, inside{};
    explicit InnerStatuses(int k) {
        const auto at = [](int s) { return static_cast<std::size_t>(static_cast<std::uint8_t>(static_cast<std::int8_t>(s))); };
        if (k == 1) {
            outside[at(0)] = inside[at(0)] = 1;
            outside[at(kPendZero)] = inside[at(kPendZero)] = 1;
        } else {
            outside[at(k - 1)] = 1;
            inside[at(-(k - 1))] = 1;
        }
    }
};

// Whitaker's layer rule at a pending point of level k (layer_value.hpp), ±inf if no neighbour is in
// the inner layer, without a branch on the point's side (a band mixes them unpredictably): the
// inside rule max(φ(q) − 1) is taken as −min(−φ(q) + 1), the same bits (rounding commutes with
// negation, and −min_of(−a, −b) is max_of(a, b), ties included).
[[gnu::always_inline]] inline float pull_value(const detail::Neighbors6& around, const float* phi, const std::int8_t* status,
                                               PointIndex i, bool outside, const InnerStatuses& inner) {
    constexpr float inf = std::numeric_limits<float>::infinity();
    const float step[2] = {inf, 1.0f};  // a neighbour not in the inner layer offers +inf: never the min
    const float sign = outside ? 1.0f : -1.0f;
    const std::uint8_t* const is_inner = outside ? inner.outside.data() : inner.inside.data();
    float best = inf;
    around.visit(i, [&](PointIndex q) __attribute__((always_inline)) {
        best = min_of(best, sign * phi[q] + step[is_inner[static_cast<std::uint8_t>(status[q])]]);
    });
    return sign * best;
}

// The claims of `sources` at one level, in order (see relayer_changes), appended to `out` through
// `buffer` a block of sources at a time (so the buffer stays small). Without a branch on a
// neighbour's status: every neighbour's status is rewritten through the level's table and recorded,
// and the count moves on only for a claim. What it reads on every visit is held in locals, not in
// a closure or a parameter object in memory: a store through std::int8_t may alias any memory, so
// those would be reloaded after every status store (as a closure: 10-20 % of a 1-thread run).
template <class Record>
void claim_from(std::span<const PointIndex> sources, const ClaimRules& rule, std::int8_t* status, const Lattice& lattice,
                const IndexDecoder& index_decoder, std::vector<Record>& buffer, std::vector<Record>& out) {
    const Lattice lat = lattice;  // locals (see above)
    const IndexDecoder decoder = index_decoder;
    const detail::Neighbors6 around(lat, decoder);  // its prefetch only
    constexpr std::size_t kClaimBlock = 4096;
    buffer.resize(6 * kClaimBlock);
    Record* const claims = buffer.data();
    for (std::size_t b = 0; b < sources.size(); b += kClaimBlock) {
        std::size_t n_claims = 0;
        for (std::size_t n = b; n < std::min(sources.size(), b + kClaimBlock); ++n) {
            if (n + detail::kAhead < sources.size()) around.prefetch(nullptr, status, sources[n + detail::kAhead]);
            const PointIndex p = sources[n];
            const std::int8_t* const r = rule[status[p] > 0 ? 1 : 0].data();  // the change's side (kPendPos > 0)
            for_each_neighbor6(lat, decoder, p, [&](PointIndex q) __attribute__((always_inline)) {
                const std::int8_t s = status[q];
                const std::int8_t after = r[static_cast<std::uint8_t>(s)];
                status[q] = after;
                claims[n_claims] = {q, s, 0.0f};
                n_claims += after != s ? 1 : 0;
            });
        }
        out.insert(out.end(), claims, claims + n_claims);
    }
}

// The decide pass of one level of change propagation over pending[b, e) (region indices): each
// point's side and its value by pull_value from a frozen state; a point claimed at this level (index
// from first_new) records its old φ first. What it reads on every point is held in locals (see
// claim_from).
template <class Record>
void decide_from(const std::size_t* pending, std::size_t b, std::size_t e, std::size_t first_new, Record* region,
                 const float* phi, const std::int8_t* status, const Lattice& lattice, const IndexDecoder& index_decoder,
                 const InnerStatuses& inner, float* value, std::uint8_t* outside) {
    const detail::Neighbors6 around(lattice, index_decoder);
    for (std::size_t m = b; m < e; ++m) {
        // The pending points are scattered (claim order), and each reads its neighbours' lines.
        if (m + detail::kAhead < e) around.prefetch(phi, status, region[pending[m + detail::kAhead]].point);
        const std::size_t r = pending[m];
        const PointIndex i = region[r].point;
        if (r >= first_new) region[r].old_phi = phi[i];
        const bool out = status[i] == kPendPos;
        outside[m] = out ? 1 : 0;
        value[m] = pull_value(around, phi, status, i, out, inner);
    }
}

// The dense repair's value pass at level k over list[b, e) of layer ±k (kOutside: +k): a point
// still on that layer (no change of layer at level k-1 reached it, so it keeps its layer and its
// inner neighbours) takes its value from the inner level; it is recorded with its value (a store and a
// count, whether it changed being unpredictable) if its bits change, to be written after the pass.
// Whitaker's rule over the inner neighbours only, without reading their statuses: neighbouring
// layers differ by at most one, so the point's neighbours are in layers k-1, k and k+1 of its side
// (the zero layer for k = 1), whose values lie in [k-1.5, k-0.5], [k-0.5, k+0.5] and [k+0.5, k+1.5]
// (far: N+1); so the min over all six is the min over the inner ones (a tie is the same value),
// and min(φ) + 1 is min(φ + 1) bit for bit (rounding is monotonic). Inside, the same with max and
// −1. Reads only; every pointer and the neighbour offsets are locals (see claim_from).
template <bool kOutside>
std::size_t pull_list(const PointIndex* list, std::size_t b, std::size_t e, std::int8_t layer, const float* phi,
                      const std::int8_t* status, const detail::Neighbors6& neighbors, PointIndex* changed, float* values) {
    const detail::Neighbors6 around = neighbors;
    std::size_t n_changed = 0;
    for (std::size_t n = b; n < e; ++n) {
        if (n + detail::kAhead < e) __builtin_prefetch(phi + list[n + detail::kAhead], 0);
        const PointIndex i = list[n];
        if (status[i] != layer) continue;  // claimed by a change of layer (pending), or moved at a level below
#if defined(__SSE2__)
        __m128 best = _mm_set_ss(kOutside ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity());
        around.visit(i, [&](PointIndex q) __attribute__((always_inline)) {
            best = kOutside ? _mm_min_ss(best, _mm_load_ss(phi + q)) : _mm_max_ss(best, _mm_load_ss(phi + q));
        });
        const float v = _mm_cvtss_f32(best) + (kOutside ? 1.0f : -1.0f);
#else
        float best = kOutside ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
        around.visit(i, [&](PointIndex q) { best = kOutside ? min_of(best, phi[q]) : max_of(best, phi[q]); });
        const float v = best + (kOutside ? 1.0f : -1.0f);
#endif
        changed[n_changed] = i;
        values[n_changed] = v;
        n_changed += same_bits(v, phi[i]) ? 0 : 1;
    }
    return n_changed;
}

// One level of the push sweep from `sources`, in order (see sweep_whole_band): claims to `next`
// (room for six per source), a far point claimed with its far mark; returns how many. What it
// reads on every visit is held in locals (see claim_from).
std::size_t sweep_from(std::span<const PointIndex> sources, const SweepRules& rule, float* phi, std::int8_t* status,
                       const Lattice& lattice, const IndexDecoder& index_decoder, PointIndex* next) {
    const detail::Neighbors6 around(lattice, index_decoder);
    constexpr float inf = std::numeric_limits<float>::infinity();
    const auto sz = static_cast<PointIndex>(lattice.stride_z());
    std::size_t n_reached = 0;
    float value[4] = {-inf, inf, 0.0f, 0.0f};  // SweepValue order; the offers per source
    for (std::size_t f = 0; f < sources.size(); ++f) {
        const PointIndex i = sources[f];
        // The sources run roughly in lattice order, so a source's +z neighbour is usually the
        // first touch of its line: fetch it for a source a few ahead (a hint; no effect on bits).
        if (f + detail::kAhead < sources.size()) {
            const PointIndex ahead = sources[f + detail::kAhead] + sz;
            __builtin_prefetch(status + ahead, 1);
            __builtin_prefetch(phi + ahead, 1);
        }
        const float v = phi[i];
        value[kOfferUp] = v + 1.0f;
        value[kOfferDown] = v - 1.0f;
        const SweepRule& r = rule[status[i] < 0 ? 1 : 0];  // the source's side
        const auto visit = [&](PointIndex q) __attribute__((always_inline)) {
            const auto s = static_cast<std::uint8_t>(status[q]);
#if defined(__SSE2__)
            // max_of(min_of(φ, hi), lo) on registers: a scalar load clears the upper lanes.
            const __m128 below = _mm_min_ss(_mm_load_ss(value + r.hi[s]), _mm_load_ss(phi + q));
            _mm_store_ss(phi + q, _mm_max_ss(_mm_load_ss(value + r.lo[s]), below));
#else
            phi[q] = max_of(min_of(phi[q], value[r.hi[s]]), value[r.lo[s]]);
#endif
            status[q] = static_cast<std::int8_t>(r.after[s]);
            next[n_reached] = q;  // a store and a count, no branch (claims are unpredictable)
            n_reached += r.claimed[s];
        };
        around.visit(i, visit);  // a source off the lattice's faces (almost every one): no test per neighbour
    }
    return n_reached;
}

// After a level of the push sweep, over its claims in the order claimed (the order reached): a far
// point claimed takes its layer ±k and joins the region with its record (far, ±(N+1); φ was its
// status, the invariant). With `up` and `down`, every claim also goes to the list of its side (the
// sign bit of ±k), a store to each list and a count, since a branch on the side (unpredictable)
// cost a quarter of the sweep's time.
template <class Region, class List>
void settle_claims(std::span<const PointIndex> claims, std::int8_t* status, std::int8_t far_out, Region& region,
                   List* up, List* down) {
    const bool split = up != nullptr;
    if (split) {
        detail::reserve_growing(*up, claims.size());
        detail::reserve_growing(*down, claims.size());
        up->resize(claims.size());
        down->resize(claims.size());
    }
    PointIndex* const u = split ? up->data() : nullptr;
    PointIndex* const d = split ? down->data() : nullptr;
    std::size_t n_up = 0, n_down = 0;
    const auto settle = [&](PointIndex q) __attribute__((always_inline)) {
        std::int8_t s = status[q];
        if (s > kFarMark || s < -kFarMark) {
            const auto was = static_cast<std::int8_t>(s > 0 ? far_out : -far_out);
            region.push_back({q, was, static_cast<float>(was)});
            s = static_cast<std::int8_t>(s > 0 ? s - kFarMark : s + kFarMark);
            status[q] = s;
        }
        return s;
    };
    if (!split) {
        for (const PointIndex q : claims) settle(q);
        return;
    }
    for (const PointIndex q : claims) {
        const std::size_t inside = static_cast<std::uint8_t>(settle(q)) >> 7;
        u[n_up] = q;
        d[n_down] = q;
        n_up += inside ^ 1u;
        n_down += inside;
    }
    up->resize(n_up);
    down->resize(n_down);
}

}  // namespace

// The dense form's value pass at level k: pull_list over the lists of layers +k and -k (reads
// only, in chunks on two threads), then the values written; the points whose value changed are
// appended to `pulled` in list order (the chunks joined in order).
void SparseField::pass_values(int k, std::vector<PointIndex>& pulled) {
    struct Part {
        std::size_t at = 0, n = 0;  // the chunk's changed points: pulled[at, at + n), pass_value_[at, ...)
    };
    float* const phi = phi_.values().data();
    const std::int8_t* const status = status_.values().data();
    const detail::Neighbors6 around(lattice(), decoder_);
    std::vector<float>& values = pass_value_.v;
    for (const auto layer : {static_cast<std::int8_t>(k), static_cast<std::int8_t>(-k)}) {
        const PointList& list = lists_[static_cast<std::size_t>(layers_ + layer)];
        const std::size_t at = pulled.size();
        pulled.resize(at + list.size());  // room for every point (reserved by repair_dense)
        if (values.size() < at + list.size()) values.resize(std::max(at + list.size(), 2 * values.size()));
        auto parts = detail::ordered_chunks<Part>(list.size(), [&](std::size_t b, std::size_t e, Part& out) {
            out.at = at + b;
            out.n = layer > 0 ? pull_list<true>(list.data(), b, e, layer, phi, status, around, pulled.data() + out.at, values.data() + out.at)
                              : pull_list<false>(list.data(), b, e, layer, phi, status, around, pulled.data() + out.at, values.data() + out.at);
        });
        std::size_t end = at;  // each chunk's points moved up behind the ones before, then written
        for (const Part& p : parts) {
            for (std::size_t n = 0; n < p.n; ++n) {
                phi[pulled[p.at + n]] = values[p.at + n];
                pulled[end + n] = pulled[p.at + n];
            }
            end += p.n;
        }
        pulled.resize(end);
    }
}

// Level k re-evaluates the points still pending from level k-1 plus every neighbour, not yet final,
// of a point that changed at level k-1 (entered or left layer ±(k-1), or took a new value there).
// Exact: a point's layer and value depend only on its neighbours one level further in, so a point
// none of whose neighbours changed keeps both (the state before the update is the layers' fixed
// point); a point whose layer is below k is final by then (it depends on levels below k-1 only).
// The dense form (`pulled`): a point's layer depends only on the layers of its neighbours one level
// further in, so only a change of layer needs propagating; a point no change of layer reaches keeps
// its layer, and its value is Whitaker's rule over its neighbours, which the value pass gives it
// (pull_list). Level 1's changes of layer are the points that left or entered the zero layer.
void SparseField::relayer_changes(std::vector<RegionPoint>& region, std::vector<PointIndex>* pulled) {
    const bool dense = pulled != nullptr;
    // The points that changed at the level below; level 0: every seed (dense: those that left or
    // entered the zero layer).
    std::vector<PointIndex> changed;
    changed.reserve(region.size());
    for (const RegionPoint& r : region)
        if (!dense || status_[r.point] != kPendZero || r.old_status != 0) changed.push_back(r.point);
    std::vector<std::size_t> pending;
    for (std::size_t r = 0; r < region.size(); ++r)
        if (status_[region[r].point] == kPendPos || status_[region[r].point] == kPendNeg) pending.push_back(r);
    std::vector<float> value;
    std::vector<std::uint8_t> outside;  // the pending point's side (a seed's old status is 0)
    struct Part {
        std::vector<std::size_t> next;  // region indices
        std::vector<PointIndex> changed;
    };
    std::int8_t* const status = status_.values().data();  // raw: see sweep_whole_band
    float* const phi = phi_.values().data();
    const Lattice lat = lattice();
    const IndexDecoder decoder = decoder_;
    for (int k = 1; k <= layers_; ++k) {
        // Claim (the first changed point in order claims, as the region's order needs): only the
        // statuses are read here; a claimed point's old φ is read in the parallel pass. Many
        // sources claim as two tasks and a seam (plane_split.hpp): the part above the plane into
        // its own list, which joins the region before the seam claims.
        const std::size_t first_new = region.size();
        const ClaimRules& rule = claim_rules(k, layers_);
        if (!splits(changed.size())) {
            claim_from(std::span<const PointIndex>(changed), rule, status, lat, decoder, claims_[0].v, region);
        } else {
            split_.v.split(changed, decoder, lat.dims().z);
            std::vector<RegionPoint>& above = claims_[1].v;
            split_.v.run([&](std::span<const PointIndex> sources, int part) {
                if (part == detail::PlaneSplit::kAbove) {
                    above.clear();
                    claim_from(sources, rule, status, lat, decoder, claims_[2].v, above);
                    return;
                }
                if (part == detail::PlaneSplit::kSeam) region.insert(region.end(), above.begin(), above.end());
                claim_from(sources, rule, status, lat, decoder, claims_[0].v, region);
            });
        }
        for (std::size_t r = first_new; r < region.size(); ++r) pending.push_back(r);
        if (pending.empty() && !dense) break;
        // Decide (reads only; Jacobi within a level, so any thread order agrees) ...
        value.resize(pending.size());
        outside.resize(pending.size());
        const InnerStatuses inner(k);
        detail::for_chunks(pending.size(), [&](std::size_t b, std::size_t e) {
            decide_from(pending.data(), b, e, first_new, region.data(), phi, status, lat, decoder, inner, value.data(),
                        outside.data());
        });
        // (dense: the points that keep layer ±k take their values from level k-1: read, then
        // written; no pending point's decision reads them) ...
        if (dense) pass_values(k, *pulled);
        // ... then write, each chunk its own points; the lists join in chunk order. Without a
        // branch on whether a point settled (unpredictable; a mispredicted branch also stalls the
        // next points' loads): every point's status and value are stored (a point that stays
        // pending gets its own back), and the lists are a store and a count.
        auto parts = detail::ordered_chunks<Part>(pending.size(), [&](std::size_t b, std::size_t e, Part& out) {
            out.next.resize(e - b);
            out.changed.resize(e - b);
            std::size_t* const next = out.next.data();
            PointIndex* const changed_here = out.changed.data();
            std::size_t n_next = 0, n_changed = 0;
            for (std::size_t m = b; m < e; ++m) {
                const std::size_t r = pending[m];
                const RegionPoint& rp = region[r];
                const PointIndex p = rp.point;
                // Not on layer k: stays pending (far if no layer takes it).
                const bool stays = std::isinf(value[m]);
                const auto layer = static_cast<std::int8_t>(outside[m] != 0 ? k : -k);
                const std::int8_t s = stays ? status[p] : layer;
                const float v = stays ? phi[p] : value[m];
                status[p] = s;
                phi[p] = v;
                next[n_next] = r;
                n_next += stays ? 1 : 0;
                changed_here[n_changed] = p;
                // Dense: only a change of layer reaches the next level (values come by the pass).
                n_changed += (stays ? std::abs(rp.old_status) == k
                                    : (layer != rp.old_status || (!dense && !same_bits(v, rp.old_phi)))) ? 1 : 0;
            }
            out.next.resize(n_next);
            out.changed.resize(n_changed);
        });
        pending.clear();
        changed.clear();
        detail::join_parts(parts, &Part::next, pending);
        detail::join_parts(parts, &Part::changed, changed);
    }
}

// Whitaker's layer rule pushed outwards instead of pulled: every point of level k-1 (final by
// then) offers φ ± 1 to its neighbours on its side that are pending or far, which keep the min
// (outside) or max (inside). A point is in layer k iff some neighbour is in layer k-1 (the zero
// layer for k = 1), and min/max are exact and order-free, so this gives the pull rule's bits
// (pull_value, the invariant checker) while visiting the 6 neighbours of each source
// instead of those of every pending point at every level (the pull re-asked the points of outer
// layers at each level). A far point reached joins the region then (its record: far, ±(N+1));
// one not reached stays as it is, so no ring of far points around the band is collected first.
// Needs the region to hold the whole band (collect_band, init_from_sdf): no final point outside it
// can be a pending point's inner neighbour. A partial region (unite_in_box) uses the pull.
void SparseField::sweep_whole_band(std::vector<RegionPoint>& region, std::span<const PointIndex> zero, bool keep_levels) {
    const std::int8_t far_out = far_outside(), far_in = far_inside();
    // A point takes its layer and the first offer when first reached; later offers of the same
    // level still count. The level lists are kept between steps (never shrunk), sized to the most
    // a level can reach (6 per source) so that a claim is a store and a count.
    PointList& from = sweep_from_.v;
    PointList& reached = sweep_next_.v;
    if (from.size() < zero.size()) from.resize(zero.size());
    std::copy(zero.begin(), zero.end(), from.begin());
    std::size_t n_from = zero.size();
    // Raw pointers and copies, read once: a store through std::int8_t (a char type, which may
    // alias anything) would otherwise make the compiler reload every member after each write.
    float* const phi = phi_.values().data();
    std::int8_t* const status = status_.values().data();
    const Lattice lat = lattice();
    const IndexDecoder decoder = decoder_;
    std::vector<PointList>& levels = level_claims_.v;
    if (keep_levels) {
        levels.resize(2 * static_cast<std::size_t>(layers_));
        for (auto& l : levels) l.clear();  // a level the sweep does not reach claims nothing
    }
    for (int k = 1; k <= layers_ && n_from > 0; ++k) {
        // Grown geometrically: a growing front must not refill them every step.
        if (reached.size() < 6 * n_from) reached.resize(std::max(6 * n_from, 2 * reached.size()));
        const SweepRules rule = sweep_rules(k, far_out, far_in);
        PointIndex* const next = reached.data();
        const std::span<const PointIndex> sources(from.data(), n_from);
        std::size_t n_reached = 0;
        if (!splits(n_from)) {
            n_reached = sweep_from(sources, rule, phi, status, lat, decoder, next);
        } else {
            // Many sources: two tasks and a seam (plane_split.hpp), each part writing its claims
            // at its own offset, moved up behind the parts before it after.
            split_.v.split(sources, decoder, lat.dims().z);
            const std::size_t room[3] = {0, 6 * split_.v.part(detail::PlaneSplit::kBelow).size(),
                                         6 * (n_from - split_.v.part(detail::PlaneSplit::kSeam).size())};
            std::size_t part_reached[3];
            split_.v.run([&](std::span<const PointIndex> part_sources, int part) {
                part_reached[part] = sweep_from(part_sources, rule, phi, status, lat, decoder, next + room[part]);
            });
            for (int part = 0; part < 3; ++part) {
                if (room[part] != n_reached) std::copy_n(next + room[part], part_reached[part], next + n_reached);
                n_reached += part_reached[part];
            }
        }
        PointList* const up = keep_levels ? &levels[2 * static_cast<std::size_t>(k - 1)] : nullptr;
        PointList* const down = keep_levels ? &levels[2 * static_cast<std::size_t>(k - 1) + 1] : nullptr;
        settle_claims(std::span<const PointIndex>(next, n_reached), status, far_out, region, up, down);
        from.swap(reached);
        n_from = n_reached;
    }
}

// The pull form for any region: each pending point asks its neighbours, level by level.
void SparseField::sweep_layers(std::span<const RegionPoint> region) {
    std::vector<PointIndex> pending;
    for (const RegionPoint& r : region)
        if (status_[r.point] == kPendPos || status_[r.point] == kPendNeg) pending.push_back(r.point);

    std::vector<float> value;
    std::vector<PointIndex> next;
    for (int k = 1; k <= layers_ && !pending.empty(); ++k) {
        value.assign(pending.size(), 0.0f);
        // Decide (reads only), then write: Jacobi within a layer, so any thread order agrees.
        const InnerStatuses inner(k);
        const detail::Neighbors6 around(lattice(), decoder_);
        const float* const phi = phi_.values().data();
        const std::int8_t* const status = status_.values().data();
        parallel_range(pending.size(), [&](std::size_t m) {
            const PointIndex i = pending[m];
            value[m] = pull_value(around, phi, status, i, status[i] == kPendPos, inner);
        });
        next.clear();
        for (std::size_t m = 0; m < pending.size(); ++m) {
            const PointIndex i = pending[m];
            if (std::isinf(value[m])) {
                next.push_back(i);
                continue;
            }
            status_[i] = static_cast<std::int8_t>(status_[i] == kPendPos ? k : -k);
            phi_[i] = value[m];
        }
        pending.swap(next);
    }
}

}  // namespace liveset
