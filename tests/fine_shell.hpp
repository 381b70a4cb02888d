// A cortex-like shell sampled at 0.5 mm, where the coarse start applies (coarse_start.hpp): for the
// tests of the coarse start in segment_image and in the Session.
#pragma once

#include <cstdint>
#include <random>

#include "liveset/grid/grid.hpp"

namespace liveset::testing {

// A ball of radius 21 mm, a dark rim (40) from 19 mm, grey (100) from 12 mm with two dark sulci one
// voxel (0.5 mm) wide cut into it, a bright core (160); Gaussian noise σ 10. Averaged over 1 mm
// blocks the sulci blur into the grey: the refinement opens them. The ROI is the ball, the truth
// the grey.
inline constexpr int kShell = 88;
struct Shell {
    Grid<float> image{Lattice({kShell, kShell, kShell}, {0.5, 0.5, 0.5}), 0.0f};
    Grid<std::uint8_t> roi{image.lattice(), 0}, truth{image.lattice(), 0};
};

inline const Shell& shell() {
    static const Shell s = [] {
        Shell out;
        std::mt19937 rng(11);
        std::normal_distribution<float> noise(0.0f, 10.0f);
        const double c = (kShell - 1) / 2.0;
        for (int z = 0; z < kShell; ++z)
            for (int y = 0; y < kShell; ++y)
                for (int x = 0; x < kShell; ++x) {
                    const Vec3d p{(x - c) * 0.5, (y - c) * 0.5, (z - c) * 0.5};
                    const double r = norm(p);
                    if (r >= 21.0) continue;
                    const bool sulcus = r >= 15.0 && ((p.x > 0.0 && p.x < 0.5) || (p.y > 0.0 && p.y < 0.5));
                    const float v = r >= 19.0 || (sulcus && r < 19.0) ? 40.0f : (r < 12.0 ? 160.0f : 100.0f);
                    out.image({x, y, z}) = v + noise(rng);
                    out.roi({x, y, z}) = 1;
                    out.truth({x, y, z}) = v == 100.0f;
                }
        return out;
    }();
    return s;
}

// A seed in the grey shell, 15.5 mm out along x (index space).
inline Vec3d shell_seed() {
    const double c = (kShell - 1) / 2.0;
    return {c + 31.0, c + 5.0, c + 5.0};
}

}  // namespace liveset::testing
