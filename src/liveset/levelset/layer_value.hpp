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

#include <algorithm>
#include <cstdint>
#include <limits>

#include "liveset/grid/grid.hpp"

namespace liveset::detail {

// Returns ±inf when the point has no neighbour for which is_inner(status) holds. `c` is the
// lattice coordinate of i (callers in hot loops decode it without division).
template <class IsInner>
float layer_value(const Grid<float>& phi, const Grid<std::int8_t>& status, PointIndex i, Vec3i c, bool outside,
                  const IsInner& is_inner) {
    const Lattice& lat = phi.lattice();
    const Vec3i d = lat.dims();
    const PointIndex stride[3] = {1, static_cast<PointIndex>(lat.stride_y()), static_cast<PointIndex>(lat.stride_z())};
    float best = outside ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
    for (int a = 0; a < 3; ++a)
        for (int dir = -1; dir <= 1; dir += 2) {
            if ((dir < 0 && c[a] == 0) || (dir > 0 && c[a] == d[a] - 1)) continue;
            const PointIndex q = dir < 0 ? i - stride[a] : i + stride[a];
            if (!is_inner(status[q])) continue;
            best = outside ? std::min(best, phi[q] + 1.0f) : std::max(best, phi[q] - 1.0f);
        }
    return best;
}

}  // namespace liveset::detail
