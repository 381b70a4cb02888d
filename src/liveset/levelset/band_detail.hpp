// Internals shared by the sparse field's update code (sparse_field.cpp, incremental_step.cpp):
// the temporary status codes of one update, 6-neighbour iteration and the serial-below-a-size
// parallel loop. Not part of the public API.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstddef>
#include <cstdint>

#include "liveset/grid/index_decoder.hpp"
#include "liveset/grid/lattice.hpp"

namespace liveset::detail {

// Temporary status codes used only inside one update (never visible outside it).
inline constexpr std::int8_t kPendPos = 100;   // to be re-layered, outside sign
inline constexpr std::int8_t kPendNeg = -100;  // to be re-layered, inside sign
inline constexpr std::int8_t kPendZero = 101;  // on the new zero layer
inline constexpr std::size_t kParallelMin = 4096;  // below this, loops run serially

inline bool is_temp(std::int8_t s) { return s >= kPendPos || s <= kPendNeg; }

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

}  // namespace liveset::detail
