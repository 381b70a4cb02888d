// An analytic head at 1.5 mm (64³) for the brain-mask tests: white matter, grey matter, CSF, dark
// skull, bright scalp, air; optionally a bridge of white-matter intensity from the brain through
// CSF and skull to the scalp (a vessel or muscle in a real head), along which a window holding the
// scalp's intensity leaks without a ROI.
#pragma once

#include <cmath>
#include <random>

#include "liveset/grid/grid.hpp"

namespace liveset::testing {

inline Grid<float> analytic_head(bool bridge) {
    Grid<float> g(Lattice({64, 64, 64}, {1.5, 1.5, 1.5}));
    std::mt19937 rng(5);
    std::normal_distribution<float> noise(0.0f, 3.0f);
    for (int z = 0; z < 64; ++z)
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x) {
                const double r = 1.5 * norm(Vec3d{x - 31.5, y - 31.5, z - 31.5});
                const float v = r < 18 ? 130.0f : r < 27 ? 95.0f : r < 29 ? 45.0f : r < 35 ? 8.0f : r < 42 ? 160.0f : 0.0f;
                g({x, y, z}) = std::abs(v + noise(rng));
            }
    if (bridge)
        for (int z = 29; z <= 34; ++z)
            for (int y = 29; y <= 34; ++y)
                for (int x = 40; x < 64; ++x)
                    if (1.5 * norm(Vec3d{x - 31.5, y - 31.5, z - 31.5}) < 42) g({x, y, z}) = 130.0f;
    return g;
}

}  // namespace liveset::testing
