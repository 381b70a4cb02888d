// The thin-front rule of a global step (sparse_field.hpp, docs/ARCHITECTURE.md "Thin fronts"): the
// zero-layer points that moved but cannot pass the front on, and the L±1 points beside them that
// enter the zero layer by their own rate.
#include <algorithm>
#include <bit>
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

// Where a pinned point's value may lie: within 0.25 of its side's edge of the zero layer.
bool near_edge(float w) { return (w <= -0.25f && w >= -0.5f) || (w >= 0.25f && w <= 0.5f); }

}  // namespace

bool SparseField::pinned(PointIndex i) const {
    const float* const phi = phi_.values().data();
    const float w = phi[i];
    if (!near_edge(w)) return false;
    // Inside (w < 0): no neighbour as deep as w − 0.5, so every upwind difference from behind is
    // under half a voxel; outside, the same mirrored. A front three voxels across or more has its
    // L∓1 points about a voxel beyond.
    bool deeper = false;
    detail::for_each_neighbor6(lattice(), decoder_, i, [&](PointIndex q) {
        deeper |= w < 0.0f ? phi[q] <= w - 0.5f : phi[q] >= w + 0.5f;
    });
    return !deeper;
}

std::vector<PointIndex> SparseField::stuck_points(std::span<const ZeroLayerEdit> edits, const float* old_phi,
                                                  std::vector<PointIndex> blocked) const {
    // Pinned: among the edits whose value changed (a full-band step's edits also hold those that
    // did not, which the incremental step leaves out), in chunk order.
    struct Part {
        std::vector<PointIndex> pinned;
    };
    auto parts = detail::ordered_chunks<Part>(edits.size(), [&](std::size_t b, std::size_t e, Part& out) {
        for (std::size_t k = b; k < e; ++k) {
            const PointIndex i = edits[k].point;
            if (std::bit_cast<std::uint32_t>(phi_[i]) != std::bit_cast<std::uint32_t>(old_phi[k]) && pinned(i))
                out.pinned.push_back(i);
        }
    });
    detail::join_parts(parts, &Part::pinned, blocked);
    return blocked;
}

std::vector<SparseField::FrontEntry> SparseField::rule_entries(const FrontRule& rule, std::span<const ZeroLayerEdit> edits,
                                                               const float* old_phi, std::vector<PointIndex> blocked) {
    try {
        return front_entries(rule, stuck_points(edits, old_phi, std::move(blocked)));
    } catch (...) {
        for (std::size_t k = 0; k < edits.size(); ++k) phi_[edits[k].point] = old_phi[k];
        throw;
    }
}

std::vector<SparseField::FrontEntry> SparseField::front_entries(const FrontRule& rule, std::span<const PointIndex> stuck) const {
    std::vector<FrontEntry> entries;
    if (stuck.empty()) return entries;
    // The other side's L±1 neighbours of every stuck point where the propagation part would move
    // the front towards them (F < 0 grows the inside, F > 0 the outside; elsewhere the front stops
    // there by the speed, as at a converged edge, the common case: no rate is asked for), once
    // each, in lattice order (so the entries are the same whatever order the stuck points came in).
    std::vector<PointIndex> ahead;
    for (const PointIndex i : stuck) {
        const std::int8_t other = phi_[i] < 0.0f ? std::int8_t{1} : std::int8_t{-1};
        detail::for_each_neighbor6(lattice(), decoder_, i, [&](PointIndex q) {
            if (status_[q] != other) return;
            const int f = rule.speed.propagation_sign(phi_, q);
            if (other > 0 ? f < 0 : f > 0) ahead.push_back(q);
        });
    }
    std::sort(ahead.begin(), ahead.end());
    ahead.erase(std::unique(ahead.begin(), ahead.end()), ahead.end());
    std::vector<double> rate(ahead.size());
    detail::for_chunks(ahead.size(), [&](std::size_t b, std::size_t e) {
        rule.speed.rates(phi_, std::span<const PointIndex>(ahead).subspan(b, e - b), std::span(rate).subspan(b, e - b));
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
