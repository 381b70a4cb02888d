// Internals shared by the sparse field's update code (sparse_field.cpp, relayer.cpp,
// incremental_step.cpp, local_edits.cpp, unite.cpp): the temporary status codes of one update,
// 6-neighbour iteration, the serial-below-a-size parallel loop and its ordered form (outputs joined
// in a fixed order), a point's text for error messages. Not part of the public API.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "liveset/grid/index_decoder.hpp"
#include "liveset/grid/lattice.hpp"
#include "liveset/levelset/sparse_field.hpp"

namespace liveset::detail {

// Temporary status codes used only inside one update (never visible outside it).
inline constexpr std::int8_t kPendPos = 100;   // to be re-layered, outside sign
inline constexpr std::int8_t kPendNeg = -100;  // to be re-layered, inside sign
inline constexpr std::int8_t kPendZero = 101;  // on the new zero layer
inline constexpr std::size_t kParallelMin = 4096;  // below this, loops run serially
// The list slot of a point not in the band (after a relist, a point that left it may keep a stale
// slot until the slots are next written; nothing reads a slot outside the band).
inline constexpr std::uint32_t kNoSlot = 0xFFFF'FFFFu;
// How far ahead a loop over scattered band points prefetches the lattice entries it will touch:
// a hint only (no effect on any result); 0.92-0.95x the whole-band step's time at 10 000-60 000
// front points on the 2-core VM (docs/BENCHMARKS.md, session 36).
inline constexpr std::size_t kAhead = 16;

// Room for n elements in a buffer kept between steps (cleared, then resized): its capacity at
// least doubles when it grows, so a growing front does not reallocate it every step (a cleared
// vector resized past its capacity gets exactly n, and fresh memory is faulted in page by page;
// on the VM clearing such pages took 0.3-5 % of a BrainWeb run, docs/BENCHMARKS.md, session 46).
template <class Vector>
void reserve_growing(Vector& v, std::size_t n) {
    if (v.capacity() < n) v.reserve(std::max(n, 2 * v.capacity()));
}

// "(x,y,z)": a lattice point in an error message.
inline std::string point_text(const Lattice& lat, PointIndex i) {
    const Vec3i c = lat.coord(i);
    std::ostringstream os;
    os << '(' << c.x << ',' << c.y << ',' << c.z << ')';
    return os.str();
}

// Whether two floats have the same bits (a change report counts a value whose bits changed).
inline bool same_bits(float a, float b) { return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b); }

inline bool is_temp(std::int8_t s) { return s >= kPendPos || s <= kPendNeg; }
// The pending code a band point of status s takes when an update marks it.
inline std::int8_t pending_of(std::int8_t s) { return s == 0 ? kPendZero : (s > 0 ? kPendPos : kPendNeg); }

template <class F>
void for_each_neighbor6(const Lattice& lat, const IndexDecoder& decode, PointIndex i, F&& f) {
    const Vec3i c = decode.coord(i);
    const Vec3i d = lat.dims();
    const auto sy = static_cast<PointIndex>(lat.stride_y());
    const auto sz = static_cast<PointIndex>(lat.stride_z());
    if (c.x > 0) f(i - 1);
    if (c.x < d.x - 1) f(i + 1);
    if (c.y > 0) f(i - sy);
    if (c.y < d.y - 1) f(i + sy);
    if (c.z > 0) f(i - sz);
    if (c.z < d.z - 1) f(i + sz);
}

// The six neighbours of a point in for_each_neighbor6's order, with one test for a point off the
// lattice's faces (almost every band point) instead of one per neighbour. Built once per loop and
// held as a local, so that its fields stay in registers across the loop's status stores (which,
// through a char type, may alias anything in memory).
class Neighbors6 {
public:
    Neighbors6(const Lattice& lattice, const IndexDecoder& decoder)
        : lat_(lattice),
          decoder_(decoder),
          sy_(static_cast<PointIndex>(lattice.stride_y())),
          sz_(static_cast<PointIndex>(lattice.stride_z())),
          last_(static_cast<PointIndex>(lattice.size() - 1)),
          core_x_(core_extent(lattice.dims().x)),
          core_y_(core_extent(lattice.dims().y)),
          core_z_(core_extent(lattice.dims().z)) {}

    template <class F>
    [[gnu::always_inline]] void visit(PointIndex i, F&& f) const {
        const Vec3i c = decoder_.coord(i);
        if (static_cast<std::uint32_t>(c.x - 1) < core_x_ && static_cast<std::uint32_t>(c.y - 1) < core_y_ &&
            static_cast<std::uint32_t>(c.z - 1) < core_z_) [[likely]] {
            f(i - 1);
            f(i + 1);
            f(i - sy_);
            f(i + sy_);
            f(i - sz_);
            f(i + sz_);
        } else {
            for_each_neighbor6(lat_, decoder_, i, f);
        }
    }

    // Fetches the lattice lines a point's six neighbours lie on (its own, which holds its x
    // neighbours, and those ±y and ±z) in φ and in the statuses (either skipped when null): a hint
    // for a loop over scattered points, issued kAhead points ahead (no effect on any result);
    // indices clamped to the lattice, so no pointer leaves it. docs/BENCHMARKS.md, session 46.
    [[gnu::always_inline]] void prefetch(const float* phi, const std::int8_t* status, PointIndex i) const {
        const PointIndex at[5] = {i, i >= sy_ ? i - sy_ : 0, std::min(i + sy_, last_), i >= sz_ ? i - sz_ : 0,
                                  std::min(i + sz_, last_)};
        for (const PointIndex a : at) {
            if (phi != nullptr) __builtin_prefetch(phi + a, 0);
            if (status != nullptr) __builtin_prefetch(status + a, 0);
        }
    }

private:
    // x - 1 < core (unsigned) iff 1 <= x <= dims - 2; a dimension below 3 has no such points.
    static std::uint32_t core_extent(int d) { return d >= 3 ? static_cast<std::uint32_t>(d - 2) : 0u; }
    Lattice lat_;
    IndexDecoder decoder_;
    PointIndex sy_, sz_, last_;
    std::uint32_t core_x_, core_y_, core_z_;
};

template <class F>
void parallel_range(std::size_t n, F&& f) {
    if (n < kParallelMin) {
        for (std::size_t i = 0; i < n; ++i) f(i);
        return;
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
    });
}

// Runs f(l) for each of `lists` layer lists: one task per list when `parallel` (each list's work
// touches only its own points' slots), else in order on the calling thread.
template <class F>
void for_each_list(int lists, bool parallel, F&& f) {
    if (!parallel) {
        for (int l = 0; l < lists; ++l) f(static_cast<std::size_t>(l));
    } else {
        tbb::parallel_for(0, lists, [&](int l) { f(static_cast<std::size_t>(l)); });
    }
}

// Runs f(begin, end) over the fixed chunks [c·K, (c+1)·K) of [0, n), in parallel from kParallelMin up.
inline constexpr std::size_t kChunk = 4096;
template <class F>
void for_chunks(std::size_t n, F&& f) {
    const std::size_t chunks = (n + kChunk - 1) / kChunk;
    const auto run = [&](std::size_t c) { f(c * kChunk, std::min(n, (c + 1) * kChunk)); };
    if (n < kParallelMin) {
        for (std::size_t c = 0; c < chunks; ++c) run(c);
    } else {
        tbb::parallel_for(std::size_t{0}, chunks, run);
    }
}

// Runs f(begin, end, part) over the fixed chunks [c·K, (c+1)·K) of [0, n), in parallel from
// kParallelMin up, each chunk appending to its own Part; returns the parts in chunk order (on one
// thread, [0, n) as one chunk). f must not depend on where the chunks end, so the outputs joined in
// that order are the serial loop's on any thread count, whatever the scheduling.
template <class Part, class F>
std::vector<Part> ordered_chunks(std::size_t n, F&& f) {
    // On one thread (an arena of one, where a small step runs, or a process limited to one) the
    // chunks would run in order anyway: one chunk gives the same joined outputs without a buffer
    // per chunk and the copies that join them (join_parts moves a single part).
    if (n > 0 && (tbb::this_task_arena::max_concurrency() == 1 ||
                  tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism) == 1)) {
        std::vector<Part> one(1);
        f(std::size_t{0}, n, one.front());
        return one;
    }
    std::vector<Part> parts((n + kChunk - 1) / kChunk);
    for_chunks(n, [&](std::size_t b, std::size_t e) { f(b, e, parts[b / kChunk]); });
    return parts;
}

// Appends the member `field` of every part to `out`, in the parts' order (moved, not copied,
// when there is one part and `out` is empty: a small update's only chunk, or any update on one
// thread).
template <class Part, class T>
void join_parts(std::vector<Part>& parts, std::vector<T> Part::*field, std::vector<T>& out) {
    if (parts.size() == 1 && out.empty()) {
        out.swap(parts.front().*field);
        return;
    }
    std::size_t total = out.size();
    for (const Part& p : parts) total += (p.*field).size();
    out.reserve(total);
    for (const Part& p : parts) out.insert(out.end(), (p.*field).begin(), (p.*field).end());
}

}  // namespace liveset::detail

namespace liveset {

// A band point into the region being repaired, once (a pending point is not added again); inline in
// every file of the step, for the hot collection loops.
[[gnu::always_inline]] inline void SparseField::mark_pending(PointIndex i, std::vector<RegionPoint>& region) {
    const std::int8_t s = status_[i];
    if (detail::is_temp(s)) return;
    region.push_back({i, s, phi_[i]});
    status_[i] = detail::pending_of(s);
}

}  // namespace liveset
