// Head geometry for the automatic brain mask (see head_geometry.hpp).
#include "liveset/segment/head_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include "liveset/segment/voxel_loops.hpp"

namespace liveset::brain_detail {

namespace {

// The solid head's voxels in the face `side` (0: index 0, 1: the last) of axis `a`, in mm².
double face_exit_mm2(const Mask& head, int a, int side) {
    const Vec3i d = head.dims();
    const Vec3d sp = head.lattice().spacing();
    const int dims[3] = {d.x, d.y, d.z};
    const double area[3] = {sp.y * sp.z, sp.x * sp.z, sp.x * sp.y};
    const int slice = side == 0 ? 0 : dims[a] - 1;
    std::size_t n = 0;
    for (int z = a == 2 ? slice : 0; z < (a == 2 ? slice + 1 : d.z); ++z)
        for (int y = a == 1 ? slice : 0; y < (a == 1 ? slice + 1 : d.y); ++y)
            for (int x = a == 0 ? slice : 0; x < (a == 0 ? slice + 1 : d.x); ++x) n += head({x, y, z}) != 0;
    return static_cast<double>(n) * area[a];
}

}  // namespace

// Slices z in parallel (counts and maxima over fixed parts: the same on any thread count).
double surface_contact(const Mask& mask, const Grid<float>& head_depth, double near_mm) {
    const Lattice& lat = mask.lattice();
    const Vec3i d = lat.dims();
    using Counts = std::pair<std::size_t, std::size_t>;  // boundary voxels, those near the surface
    const Counts counts = voxel_loops::reduce(
        static_cast<std::size_t>(d.z), 1, Counts{0, 0},
        [&](std::size_t zb, std::size_t ze, Counts c) {
            for (auto z = static_cast<int>(zb); z < static_cast<int>(ze); ++z)
                for (int y = 0; y < d.y; ++y)
                    for (int x = 0; x < d.x; ++x) {
                        if (mask({x, y, z}) == 0) continue;
                        bool edge = false;
                        for (int k = 0; k < 6 && !edge; ++k) {
                            Vec3i q{x, y, z};
                            q[k / 2] += k % 2 ? 1 : -1;
                            edge = lat.contains(q) && mask(q) == 0;
                        }
                        if (!edge) continue;
                        ++c.first;
                        c.second += head_depth({x, y, z}) <= near_mm;
                    }
            return c;
        },
        [](Counts a, Counts b) { return Counts{a.first + b.first, a.second + b.second}; });
    return counts.first > 0 ? static_cast<double>(counts.second) / static_cast<double>(counts.first) : 0.0;
}

double head_top(const Mask& head, const Vertical& up) {
    const Vec3i d = head.dims();
    return voxel_loops::reduce(
        static_cast<std::size_t>(d.z), 1, -std::numeric_limits<double>::infinity(),
        [&](std::size_t zb, std::size_t ze, double top) {
            for (auto z = static_cast<int>(zb); z < static_cast<int>(ze); ++z)
                for (int y = 0; y < d.y; ++y)
                    for (int x = 0; x < d.x; ++x)
                        if (head({x, y, z}) != 0) top = std::max(top, up.height({x, y, z}));
            return top;
        },
        [](double a, double b) { return std::max(a, b); });
}

Vertical vertical(const Mask& head, bool from_header) {
    Vertical v;
    const Lattice& lat = head.lattice();
    const Vec3d sp = lat.spacing();
    const double step[3] = {sp.x, sp.y, sp.z};
    if (from_header) {
        const double z0 = lat.to_world({0, 0, 0}).z;
        v.g[0] = lat.to_world({1, 0, 0}).z - z0;
        v.g[1] = lat.to_world({0, 1, 0}).z - z0;
        v.g[2] = lat.to_world({0, 0, 1}).z - z0;
        int a = 0;  // the axis most along the superior axis (per millimetre)
        for (int k = 1; k < 3; ++k)
            if (std::abs(v.g[k]) / step[k] > std::abs(v.g[a]) / step[a]) a = k;
        v.exit_mm2 = face_exit_mm2(head, a, v.g[a] > 0 ? 0 : 1);
        return v;
    }
    int best_a = 2, best_side = 0;
    for (int a = 0; a < 3; ++a)
        for (int side = 0; side < 2; ++side) {
            const double e = face_exit_mm2(head, a, side);
            if (e > v.exit_mm2) v.exit_mm2 = e, best_a = a, best_side = side;
        }
    v.g[best_a] = best_side == 0 ? step[best_a] : -step[best_a];
    return v;
}

Mask cranial(const Mask& head, const Vertical& up, double extent_mm, std::size_t& below) {
    below = 0;
    if (extent_mm <= 0) return head;
    const Vec3i d = head.dims();
    const double top = head_top(head, up);
    Mask out = head;
    below = voxel_loops::reduce(
        static_cast<std::size_t>(d.z), 1, std::size_t{0},
        [&](std::size_t zb, std::size_t ze, std::size_t n) {
            for (auto z = static_cast<int>(zb); z < static_cast<int>(ze); ++z)
                for (int y = 0; y < d.y; ++y)
                    for (int x = 0; x < d.x; ++x)
                        if (out({x, y, z}) != 0 && up.height({x, y, z}) < top - extent_mm) {
                            out({x, y, z}) = 0;
                            ++n;
                        }
            return n;
        },
        [](std::size_t a, std::size_t b) { return a + b; });
    return out;
}

double head_diameter_mm(const Mask& head, const Vertical& up, double depth_mm) {
    const Vec3i d = head.dims();
    const double layer_mm = std::max({std::abs(up.g[0]), std::abs(up.g[1]), std::abs(up.g[2])});
    const double top = head_top(head, up);
    using Layers = std::vector<std::size_t>;  // voxels per layer below the top (counts: any order)
    const Layers layer = voxel_loops::reduce(
        static_cast<std::size_t>(d.z), 1, Layers(static_cast<std::size_t>(std::lround(depth_mm / layer_mm)) + 1, 0),
        [&](std::size_t zb, std::size_t ze, Layers n) {
            for (auto z = static_cast<int>(zb); z < static_cast<int>(ze); ++z)
                for (int y = 0; y < d.y; ++y)
                    for (int x = 0; x < d.x; ++x) {
                        if (head({x, y, z}) == 0) continue;
                        const auto k = static_cast<std::size_t>(std::lround((top - up.height({x, y, z})) / layer_mm));
                        if (k < n.size()) ++n[k];
                    }
            return n;
        },
        voxel_loops::add_counts);
    const Vec3d sp = head.lattice().spacing();
    const double widest = static_cast<double>(*std::max_element(layer.begin(), layer.end())) * sp.x * sp.y * sp.z / layer_mm;  // mm²
    return 2.0 * std::sqrt(widest / std::numbers::pi);
}

double cut_contact_mm2(const Mask& brain, const Vertical& up, double cut) {
    const double layer_mm = std::max({std::abs(up.g[0]), std::abs(up.g[1]), std::abs(up.g[2])});
    const double slab = layer_mm * std::ceil(3.0 / layer_mm - 1e-9);
    const Vec3i d = brain.dims();
    const std::size_t n = voxel_loops::reduce(
        static_cast<std::size_t>(d.z), 1, std::size_t{0},
        [&](std::size_t zb, std::size_t ze, std::size_t c) {
            for (auto z = static_cast<int>(zb); z < static_cast<int>(ze); ++z)
                for (int y = 0; y < d.y; ++y)
                    for (int x = 0; x < d.x; ++x)
                        if (brain({x, y, z}) != 0) {
                            const double h = up.height({x, y, z});
                            c += h >= cut && h < cut + slab;
                        }
            return c;
        },
        [](std::size_t a, std::size_t b) { return a + b; });
    const Vec3d s = brain.lattice().spacing();
    return static_cast<double>(n) * s.x * s.y * s.z / slab;
}

}  // namespace liveset::brain_detail
