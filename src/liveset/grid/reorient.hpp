// Canonical axis order: the same physical image stored with its axes permuted or reversed (a .mnc
// read back by ITK, a NIfTI written RAS- instead of LPS-ordered) reordered to one array, so that
// methods that work on the index grid (N4's subsampled B-spline fit) give the same answer for
// every storage order. Exact: voxels are moved, never resampled.
#pragma once

#include <array>

#include "liveset/grid/grid.hpp"

namespace liveset {

// New axis a is old axis `axis[a]`, reversed when `flip[a]`.
struct AxisOrder {
    std::array<int, 3> axis{0, 1, 2};
    std::array<bool, 3> flip{false, false, false};
    bool identity() const { return axis == std::array<int, 3>{0, 1, 2} && flip == std::array<bool, 3>{false, false, false}; }
};

// The order whose axes point along +x, +y, +z of the world as closely as the direction allows
// (each old axis goes to the world axis it has the largest cosine with; ties: the lower axis first).
AxisOrder canonical_order(const Lattice& lattice);

// The lattice of the reordered grid: same voxel centres in the world, axes in `order`.
Lattice reordered(const Lattice& lattice, const AxisOrder& order);

// Old index of the voxel at new index `n` (dims: the old lattice's).
inline Vec3i old_index(Vec3i n, const AxisOrder& order, Vec3i dims) {
    Vec3i o{0, 0, 0};
    for (int a = 0; a < 3; ++a) {
        const int k = order.axis[static_cast<std::size_t>(a)];
        o[k] = order.flip[static_cast<std::size_t>(a)] ? dims[k] - 1 - n[a] : n[a];
    }
    return o;
}

// `grid` with its axes in `order`.
template <class T>
Grid<T> reorder(const Grid<T>& grid, const AxisOrder& order) {
    Grid<T> out(reordered(grid.lattice(), order));
    const Vec3i d = out.dims();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) out({x, y, z}) = grid(old_index({x, y, z}, order, grid.dims()));
    return out;
}

// The inverse of reorder(): `reordered_grid` back onto `original`.
template <class T>
Grid<T> restore(const Grid<T>& reordered_grid, const AxisOrder& order, const Lattice& original) {
    Grid<T> out(original);
    const Vec3i d = reordered_grid.dims();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) out(old_index({x, y, z}, order, original.dims())) = reordered_grid({x, y, z});
    return out;
}

}  // namespace liveset
