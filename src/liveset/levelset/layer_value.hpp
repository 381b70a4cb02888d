// The value an outer-layer point takes from the layer inside it (Whitaker 1998): over its
// neighbours in layer ±(k-1), φ = min φ(q) + 1 outside, max φ(q) − 1 inside. Every point of layer k
// therefore depends only on points within Manhattan distance k. Shared by the update and the
// invariant checker so both agree bitwise.
//
// Measured trade-off (docs/ARCHITECTURE.md): these first-order values bias the difference-of-
// normals curvature at zero-layer points by about +5 % on spheres (exact signed distances: 0 %);
// a two-stage first-order Eikonal reconstruction was tried and is worse (+11 %), because its error
// is one-sided across the front.
#pragma once

#include <cstdint>
#include <limits>

#include "liveset/grid/float_min_max.hpp"
#include "liveset/grid/grid.hpp"

namespace liveset::detail {

// layer_value() for a side fixed at compile time: the six neighbours in the order -x, +x, -y, +y,
// -z, +z, unrolled.
template <bool Outside, class IsInner>
[[gnu::always_inline]] inline float layer_value_side(const Grid<float>& phi, const Grid<std::int8_t>& status, PointIndex i,
                                                     Vec3i c, const IsInner& is_inner) {
    const Lattice& lat = phi.lattice();
    const Vec3i d = lat.dims();
    const auto sy = static_cast<PointIndex>(lat.stride_y()), sz = static_cast<PointIndex>(lat.stride_z());
    constexpr float none = Outside ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
    float best = none;
    // Without a branch on the neighbour's status (unpredictable in a moving band): a neighbour
    // not in the inner layer offers φ ± ∞ = ±∞, which never wins; φ − 1 is φ + (−1) bit for bit.
    const float step[2] = {none, Outside ? 1.0f : -1.0f};
    const auto offer = [&](PointIndex q) {
        const float candidate = phi[q] + step[is_inner(status[q]) ? 1 : 0];
        best = Outside ? min_of(best, candidate) : max_of(best, candidate);
    };
    if (c.x != 0) offer(i - 1);
    if (c.x != d.x - 1) offer(i + 1);
    if (c.y != 0) offer(i - sy);
    if (c.y != d.y - 1) offer(i + sy);
    if (c.z != 0) offer(i - sz);
    if (c.z != d.z - 1) offer(i + sz);
    return best;
}

// Returns ±inf when the point has no neighbour for which is_inner(status) holds. `c` is the
// lattice coordinate of i (callers in hot loops decode it without division).
template <class IsInner>
float layer_value(const Grid<float>& phi, const Grid<std::int8_t>& status, PointIndex i, Vec3i c, bool outside,
                  const IsInner& is_inner) {
    return outside ? layer_value_side<true>(phi, status, i, c, is_inner) : layer_value_side<false>(phi, status, i, c, is_inner);
}

}  // namespace liveset::detail
