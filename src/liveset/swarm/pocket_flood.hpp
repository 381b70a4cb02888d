// Whether an edit separates a small pocket from the outside: one flood per start, all run by turns,
// joined where they meet, so the common case (the pieces meet around the edit) costs a loop, not a limit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "liveset/grid/lattice.hpp"

namespace liveset {

// The outside regions (6-connected) around some voxels just flipped inside. `starts` are outside
// voxels in the lattice (their face neighbours); seals() is true when they lie in two or more
// regions and one of those holds at most `limit` voxels and does not reach the lattice border: the
// flip separated it off (a pocket). One region only — the pieces join elsewhere, however small the
// region is — is no separation, and false.
//
// The floods (one per distinct start) take a voxel each in turn; a flood that reaches a voxel of
// another joins it (union-find); a region that passes `limit` voxels or touches the border stops
// growing ("large"). The answer is known when one region is left (false), when a region runs out of
// voxels while not large (true: it is a whole region, and at least one other exists) or when every
// region is large (false). It depends on the regions only, not on the order of the starts.
// Marks are reused across calls (a new range of stamps per call, nothing cleared).
class PocketFlood {
public:
    template <class OutsideAt>
    bool seals(const Lattice& lat, const OutsideAt& outside_at, std::span<const Vec3i> starts, std::size_t limit);

private:
    std::uint32_t find(std::uint32_t f) {
        while (parent_[f] != f) f = parent_[f] = parent_[parent_[f]];
        return f;
    }
    // Joins the regions of floods a and b; returns the number of regions left.
    std::size_t join(std::uint32_t a, std::uint32_t b, std::size_t limit);
    bool open(const Lattice& lat, std::span<const Vec3i> starts, std::size_t limit);
    void enter(std::uint32_t f, Vec3i q, PointIndex j, Vec3i dims, std::size_t limit);

    std::vector<std::uint32_t> stamp_;  // per lattice point: base_ + flood id when visited in this call
    std::uint32_t base_ = 0, floods_ = 0;
    std::size_t regions_ = 0;
    std::vector<std::vector<Vec3i>> queue_;
    std::vector<std::size_t> head_;
    std::vector<std::uint32_t> parent_;
    std::vector<std::size_t> count_;      // per region root: voxels visited
    std::vector<std::uint32_t> pending_;  // per region root: member floods with voxels still queued
    std::vector<std::uint8_t> large_;     // per region root
    std::vector<std::uint32_t> live_;     // floods still worth a turn
};

inline std::size_t PocketFlood::join(std::uint32_t a, std::uint32_t b, std::size_t limit) {
    a = find(a);
    b = find(b);
    if (a == b) return regions_;
    if (count_[a] < count_[b]) std::swap(a, b);
    parent_[b] = a;
    count_[a] += count_[b];
    pending_[a] += pending_[b];
    large_[a] = large_[a] || large_[b] || count_[a] > limit;
    return --regions_;
}

inline void PocketFlood::enter(std::uint32_t f, Vec3i q, PointIndex j, Vec3i dims, std::size_t limit) {
    stamp_[j] = base_ + f;
    queue_[f].push_back(q);
    const std::uint32_t r = find(f);
    const bool border = q.x == 0 || q.y == 0 || q.z == 0 || q.x == dims.x - 1 || q.y == dims.y - 1 || q.z == dims.z - 1;
    if (++count_[r] > limit || border) large_[r] = 1;
}

// One flood per distinct start (a start met twice is one flood). False when fewer than two.
inline bool PocketFlood::open(const Lattice& lat, std::span<const Vec3i> starts, std::size_t limit) {
    if (stamp_.size() != lat.size() || std::uint64_t{base_} + floods_ + starts.size() >= UINT32_MAX) {
        stamp_.assign(lat.size(), 0);
        base_ = 0;
        floods_ = 0;
    }
    base_ += floods_ + 1;  // stamps below base_ are earlier calls'
    floods_ = 0;
    live_.clear();
    for (const Vec3i s : starts) {
        const PointIndex j = lat.index(s);
        if (stamp_[j] >= base_) continue;
        const std::uint32_t f = floods_++;
        if (queue_.size() < floods_) {
            queue_.resize(floods_);
            head_.resize(floods_);
            parent_.resize(floods_);
            count_.resize(floods_);
            pending_.resize(floods_);
            large_.resize(floods_);
        }
        queue_[f].clear();
        head_[f] = 0;
        parent_[f] = f;
        count_[f] = 0;
        pending_[f] = 1;
        large_[f] = 0;
        enter(f, s, j, lat.dims(), limit);
        live_.push_back(f);
    }
    regions_ = floods_;
    return regions_ >= 2;
}

template <class OutsideAt>
bool PocketFlood::seals(const Lattice& lat, const OutsideAt& outside_at, std::span<const Vec3i> starts, std::size_t limit) {
    if (!open(lat, starts, limit)) return false;
    const Vec3i dims = lat.dims();
    const auto sy = static_cast<PointIndex>(lat.stride_y()), sz = static_cast<PointIndex>(lat.stride_z());
    const PointIndex step[6] = {PointIndex(0) - 1, 1, PointIndex(0) - sy, sy, PointIndex(0) - sz, sz};
    while (!live_.empty()) {
        std::size_t kept = 0;
        for (const std::uint32_t f : live_) {
            if (head_[f] == queue_[f].size() || large_[find(f)]) continue;  // drops out of the turns
            // A queued voxel is off the border: one on it made its region large.
            const Vec3i p = queue_[f][head_[f]++];
            const PointIndex i = lat.index(p);
            for (int k = 0; k < 6; ++k) {
                const PointIndex j = i + step[k];  // unsigned wrap: i - 1 etc. (p is off the border)
                if (!outside_at(j)) continue;
                if (stamp_[j] >= base_) {
                    if (join(f, stamp_[j] - base_, limit) == 1) return false;
                    continue;
                }
                Vec3i q = p;
                q[k / 2] += (k % 2) ? 1 : -1;
                enter(f, q, j, dims, limit);
            }
            const std::uint32_t r = find(f);
            if (head_[f] == queue_[f].size() && --pending_[r] == 0 && !large_[r]) return true;
            live_[kept++] = f;
        }
        live_.resize(kept);
    }
    return false;
}

}  // namespace liveset
