// Builders of small binary test masks (boxes, balls, shells, tori, drilled holes) for the eval tests.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>

#include "liveset/grid/grid.hpp"

namespace liveset::test {

using Mask = Grid<std::uint8_t>;

// Sets every voxel whose index coordinate satisfies `inside` to `value`.
inline void paint(Mask& m, const std::function<bool(Vec3d)>& inside, std::uint8_t value = 1) {
    const Vec3i d = m.dims();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x)
                if (inside(Vec3d{double(x), double(y), double(z)})) m({x, y, z}) = value;
}

// Voxels with lo <= index < hi on every axis.
inline void paint_box(Mask& m, Vec3i lo, Vec3i hi, std::uint8_t value = 1) {
    for (int z = lo.z; z < hi.z; ++z)
        for (int y = lo.y; y < hi.y; ++y)
            for (int x = lo.x; x < hi.x; ++x) m.at({x, y, z}) = value;
}

// Ball of radius r (index units) about c: voxel centres with |p - c| <= r.
inline void paint_ball(Mask& m, Vec3d c, double r, std::uint8_t value = 1) {
    paint(m, [&](Vec3d p) { return norm(p - c) <= r; }, value);
}

// Ball in physical units: |spacing ⊙ (p - c)| <= r_mm.
inline void paint_ball_mm(Mask& m, Vec3d c, double r_mm, std::uint8_t value = 1) {
    const Vec3d s = m.lattice().spacing();
    paint(m, [&](Vec3d p) { return norm(hadamard(p - c, s)) <= r_mm; }, value);
}

}  // namespace liveset::test
