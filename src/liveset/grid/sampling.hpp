// Sampling and differentiation on a Grid<float> in index space (unit spacing): trilinear
// interpolation, central-difference gradients and the Godunov upwind gradient magnitude used by the
// level-set update. Out-of-lattice stencil points read the nearest border value.
#pragma once

#include <algorithm>
#include <cmath>

#include "liveset/grid/float_min_max.hpp"
#include "liveset/grid/grid.hpp"

namespace liveset {

// Trilinear interpolation at a continuous index-space position (clamped to the lattice).
inline float trilinear(const Grid<float>& g, Vec3d p) {
    const Vec3i d = g.dims();
    const double x = std::clamp(p.x, 0.0, static_cast<double>(d.x - 1));
    const double y = std::clamp(p.y, 0.0, static_cast<double>(d.y - 1));
    const double z = std::clamp(p.z, 0.0, static_cast<double>(d.z - 1));
    const int x0 = std::min(static_cast<int>(x), std::max(d.x - 2, 0));
    const int y0 = std::min(static_cast<int>(y), std::max(d.y - 2, 0));
    const int z0 = std::min(static_cast<int>(z), std::max(d.z - 2, 0));
    const double fx = x - x0, fy = y - y0, fz = z - z0;
    if (d.x >= 2 && d.y >= 2 && d.z >= 2 && x0 >= 0 && y0 >= 0 && z0 >= 0) {
        // The cell's 8 corners are inside the lattice: read them directly (the same values, so the
        // same bits, as the clamped reads below, without 8 clamps and index products). A position
        // that is not a number never gets here: it takes the clamped reads, inside the lattice.
        const Lattice& l = g.lattice();
        const std::size_t sy = l.stride_y(), sz = l.stride_z();
        const float* v = g.values().data() + l.index({x0, y0, z0});
        const auto at = [&](std::size_t o) { return static_cast<double>(v[o]); };
        const double c00 = at(0) * (1 - fx) + at(1) * fx;
        const double c10 = at(sy) * (1 - fx) + at(sy + 1) * fx;
        const double c01 = at(sz) * (1 - fx) + at(sz + 1) * fx;
        const double c11 = at(sy + sz) * (1 - fx) + at(sy + sz + 1) * fx;
        const double c0 = c00 * (1 - fy) + c10 * fy;
        const double c1 = c01 * (1 - fy) + c11 * fy;
        return static_cast<float>(c0 * (1 - fz) + c1 * fz);
    }
    auto v = [&](int i, int j, int k) { return static_cast<double>(g.clamped({x0 + i, y0 + j, z0 + k})); };
    const double c00 = v(0, 0, 0) * (1 - fx) + v(1, 0, 0) * fx;
    const double c10 = v(0, 1, 0) * (1 - fx) + v(1, 1, 0) * fx;
    const double c01 = v(0, 0, 1) * (1 - fx) + v(1, 0, 1) * fx;
    const double c11 = v(0, 1, 1) * (1 - fx) + v(1, 1, 1) * fx;
    const double c0 = c00 * (1 - fy) + c10 * fy;
    const double c1 = c01 * (1 - fy) + c11 * fy;
    return static_cast<float>(c0 * (1 - fz) + c1 * fz);
}

// Central-difference gradient at a lattice point (one-sided at the lattice border).
inline Vec3f central_gradient(const Grid<float>& g, Vec3i p) {
    const Vec3i d = g.dims();
    if (p.x >= 1 && p.y >= 1 && p.z >= 1 && p.x <= d.x - 2 && p.y <= d.y - 2 && p.z <= d.z - 2) {
        // Every 6-neighbour inside: the same arithmetic without the clamping, so the same bits.
        const Lattice& l = g.lattice();
        const std::size_t sy = l.stride_y(), sz = l.stride_z(), i = l.index(p);
        const float* v = g.values().data();
        return {(v[i + 1] - v[i - 1]) / 2.0f, (v[i + sy] - v[i - sy]) / 2.0f, (v[i + sz] - v[i - sz]) / 2.0f};
    }
    Vec3f r;
    for (int a = 0; a < 3; ++a) {
        Vec3i lo = p, hi = p;
        lo[a] = std::max(p[a] - 1, 0);
        hi[a] = std::min(p[a] + 1, d[a] - 1);
        const int span = hi[a] - lo[a];
        r[a] = span > 0 ? (g(hi) - g(lo)) / static_cast<float>(span) : 0.0f;
    }
    return r;
}

// Gradient by central differences of the trilinear interpolant at a continuous position
// (half-voxel step), for agents and samples between lattice points.
inline Vec3f interpolated_gradient(const Grid<float>& g, Vec3d p) {
    Vec3f r;
    for (int a = 0; a < 3; ++a) {
        Vec3d lo = p, hi = p;
        lo[a] -= 0.5;
        hi[a] += 0.5;
        r[a] = trilinear(g, hi) - trilinear(g, lo);
    }
    return r;
}

// Godunov upwind |∇φ| for ∂φ/∂t = F |∇φ| (φ < 0 inside, F > 0 moves the front inwards).
// Information flows from where the front comes from: for F > 0 the upwind choice is
// max(D-,0)/min(D+,0) mirrored, see Osher & Fedkiw, "Level Set Methods", ch. 6. Each axis's
// differences are multiplied by `scale` (the level set's h_min/h per axis: |∇φ| per finest voxel;
// 1.0f keeps the unscaled bits).
inline float upwind_gradient_norm(const Grid<float>& g, Vec3i p, float speed, Vec3f scale = {1.0f, 1.0f, 1.0f}) {
    // One axis's squared upwind difference from its backward (D-) and forward (D+) differences,
    // with std::min's and std::max's bits but no branch on the differences' signs (min_of).
    const auto axis = [speed](float dm, float dp) {
        if (speed > 0) {  // φ increases: equivalent to outward speed -F < 0
            const float a1 = min_of(dm, 0.0f), a2 = max_of(dp, 0.0f);
            return max_of(a1 * a1, a2 * a2);
        }
        const float a1 = max_of(dm, 0.0f), a2 = min_of(dp, 0.0f);
        return max_of(a1 * a1, a2 * a2);
    };
    const Vec3i d = g.dims();
    float sum = 0.0f;
    if (p.x >= 1 && p.y >= 1 && p.z >= 1 && p.x <= d.x - 2 && p.y <= d.y - 2 && p.z <= d.z - 2) {
        // Every 6-neighbour inside: the same arithmetic without the clamping, so the same bits.
        const Lattice& l = g.lattice();
        const std::size_t i = l.index(p), stride[3] = {1, l.stride_y(), l.stride_z()};
        const float* v = g.values().data();
        const float c = v[i];
        for (int a = 0; a < 3; ++a) sum += axis((c - v[i - stride[a]]) * scale[a], (v[i + stride[a]] - c) * scale[a]);
        return std::sqrt(sum);
    }
    const float c = g(p);
    for (int a = 0; a < 3; ++a) {
        Vec3i lo = p, hi = p;
        lo[a] -= 1;
        hi[a] += 1;
        sum += axis((c - g.clamped(lo)) * scale[a], (g.clamped(hi) - c) * scale[a]);
    }
    return std::sqrt(sum);
}

}  // namespace liveset
