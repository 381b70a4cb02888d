// The thin-front rule of a global step (sparse_field.hpp, docs/ARCHITECTURE.md "Thin fronts"): the
// zero-layer points that moved but cannot pass the front on, and the L±1 points beside them that
// enter the zero layer by their own rate.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include "liveset/levelset/band_detail.hpp"
#include "liveset/levelset/sparse_field.hpp"

namespace liveset {

namespace {

// The stuck points' L±1 neighbours on their other side (the candidates of points_ahead), each with
// that side's status. With `test_pinned` (stuck: the pinned test's candidates, on their side by
// their value) a point counts only if no neighbour lies half a voxel or more beyond its value
// (inside, w < 0: none as deep as w - 0.5, so every upwind difference from behind is under half a
// voxel; outside mirrored): the pinned test; a front three voxels across or more has its L∓1
// points about a voxel beyond. Without (stuck: blocked points, each with its other side), every
// one counts. One visit of the six neighbours reads both tests' values, their lines fetched
// kAhead points ahead (the points are scattered over the zero layer).
template <bool test_pinned, class Stuck>
void other_side(std::span<const Stuck> stuck, const float* phi, const std::int8_t* status, const detail::Neighbors6& around,
                std::vector<PointIndex>& sides, std::vector<std::int8_t>& others) {
    for (std::size_t j = 0; j < stuck.size(); ++j) {
        PointIndex i;
        std::int8_t other;
        float w = 0.0f;
        if constexpr (test_pinned) {
            if (j + detail::kAhead < stuck.size()) around.prefetch(phi, status, stuck[j + detail::kAhead]);
            i = stuck[j];
            w = phi[i];
            other = w < 0.0f ? std::int8_t{1} : std::int8_t{-1};
        } else {
            if (j + detail::kAhead < stuck.size()) around.prefetch(nullptr, status, stuck[j + detail::kAhead].point);
            i = stuck[j].point;
            other = stuck[j].other;
        }
        PointIndex side[6];
        std::size_t n = 0;
        bool deeper = false;
        around.visit(i, [&](PointIndex q) {
            side[n] = q;
            n += status[q] == other ? 1 : 0;
            if constexpr (test_pinned) deeper |= w < 0.0f ? phi[q] <= w - 0.5f : phi[q] >= w + 0.5f;
        });
        if (deeper) continue;
        sides.insert(sides.end(), side, side + n);
        others.insert(others.end(), n, other);
    }
}

}  // namespace

std::vector<PointIndex> SparseField::points_ahead(const FrontRule& rule, std::span<const PointIndex> near,
                                                  std::span<const StuckPoint> blocked) const {
    const float* const phi = phi_.values().data();
    const std::int8_t* const status = status_.values().data();
    const detail::Neighbors6 around(lattice(), decoder_);
    // A blocked point needs no pinned test (it is stuck either way, with the same neighbours
    // ahead); one blocked without an L∓1 neighbour on the other side (step 2's ±3) has none. Of
    // the candidates, those towards which the propagation part would move the front: F < 0 grows
    // the inside, F > 0 the outside; elsewhere the front stops there by the speed, as at a
    // converged edge, the common case (no rate is asked for). Blocked points' candidates first,
    // then the pinned ones', each in chunks.
    struct Ahead {
        std::vector<PointIndex> ahead;
    };
    const auto towards = [&](std::vector<PointIndex>& sides, const std::vector<std::int8_t>& others, Ahead& out) {
        std::vector<std::int8_t> sign(sides.size());
        rule.speed.propagation_signs(phi_, sides, sign);
        for (std::size_t k = 0; k < sides.size(); ++k)
            if (others[k] > 0 ? sign[k] < 0 : sign[k] > 0) out.ahead.push_back(sides[k]);
    };
    const std::size_t n_blocked = blocked.size();
    auto parts = detail::ordered_chunks<Ahead>(n_blocked + near.size(), [&](std::size_t b, std::size_t e, Ahead& out) {
        std::vector<PointIndex> sides;
        std::vector<std::int8_t> others;
        if (b < n_blocked)
            other_side<false>(blocked.subspan(b, std::min(e, n_blocked) - b), phi, status, around, sides, others);
        if (e > n_blocked) {
            const std::size_t from = std::max(b, n_blocked) - n_blocked;
            other_side<true>(near.subspan(from, e - n_blocked - from), phi, status, around, sides, others);
        }
        towards(sides, others, out);
    });
    // Once each, in lattice order (the same whatever order the stuck points came in).
    std::vector<PointIndex> ahead;
    detail::join_parts(parts, &Ahead::ahead, ahead);
    std::sort(ahead.begin(), ahead.end());
    ahead.erase(std::unique(ahead.begin(), ahead.end()), ahead.end());
    return ahead;
}

std::vector<SparseField::FrontEntry> SparseField::rule_entries(const FrontRule& rule, std::span<const PointIndex> near,
                                                               std::span<const StuckPoint> blocked,
                                                               std::span<const ZeroLayerEdit> edits, const float* old_phi) {
    try {
        return front_entries(rule, points_ahead(rule, near, blocked));
    } catch (...) {
        for (std::size_t k = 0; k < edits.size(); ++k) phi_[edits[k].point] = old_phi[k];
        throw;
    }
}

std::vector<SparseField::FrontEntry> SparseField::front_entries(const FrontRule& rule, std::span<const PointIndex> ahead) const {
    std::vector<FrontEntry> entries;
    if (ahead.empty()) return entries;
    std::vector<double> rate(ahead.size());
    detail::for_chunks(ahead.size(), [&](std::size_t b, std::size_t e) {
        rule.speed.rates(phi_, ahead.subspan(b, e - b), std::span(rate).subspan(b, e - b));
    });
    // Each steps as a zero-layer point would (Δ clamped to ±cfl, the float sum of move_values) and
    // enters where that brings it into the zero layer's range on its own side: [0, 0.5) from L+1
    // (φ ≥ 0.5 there and |Δ| ≤ 0.5, so never below 0), (-0.5, 0) from L-1 (where -0.5 + 0.5 gives
    // +0, outside, it does not enter), so no entry changes sign.
    for (std::size_t k = 0; k < ahead.size(); ++k) {
        if (!std::isfinite(rate[k])) throw std::runtime_error("speed term returned a non-finite value");
        const PointIndex j = ahead[k];
        const float v = phi_[j] + static_cast<float>(std::clamp(rule.dt * rate[k], -rule.cfl, rule.cfl));
        if (status_[j] > 0 ? v < 0.5f : (v > -0.5f && v < 0.0f)) entries.push_back({j, v});
    }
    return entries;
}

std::size_t SparseField::enter_zero_layer(std::span<const FrontEntry> entries, RegionPoint* out) {
    // Where a hand-over took the point (its status is no longer ±1), the hand-over's value stands.
    std::size_t n = 0;
    for (const FrontEntry& entry : entries) {
        const PointIndex j = entry.point;
        const std::int8_t s = status_[j];
        if (s != 1 && s != -1) continue;
        out[n++] = {j, s, phi_[j]};
        status_[j] = detail::kPendZero;
        phi_[j] = entry.phi;
    }
    return n;
}

}  // namespace liveset
