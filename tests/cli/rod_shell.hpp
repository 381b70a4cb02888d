// The cut rule's end-to-end case, shared by the CLI and scripted-session tests: a 32^3 shell
// (grey 100 for 9 < r <= 12, white 130 inside, CSF 50 outside) whose mask took in a one-voxel rod of
// the core's tissue along x through the centre (16, 16, 16) — a handle: genus 1.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>

#include "liveset/eval/topology.hpp"
#include "liveset/grid/grid.hpp"

namespace liveset::testing {

struct RodShell {
    Grid<float> image{Lattice({32, 32, 32}), 50.0f};
    Grid<std::uint8_t> mask{Lattice({32, 32, 32}), 0}, rod{Lattice({32, 32, 32}), 0};
};

inline RodShell rod_shell() {
    RodShell c;
    for (int z = 0; z < 32; ++z)
        for (int y = 0; y < 32; ++y)
            for (int x = 0; x < 32; ++x) {
                const double r = norm(Vec3d{x - 16.0, y - 16.0, z - 16.0});
                c.rod({x, y, z}) = r <= 9 && y == 16 && z == 16;
                c.image({x, y, z}) = r <= 9 ? 130.0f : r <= 12 ? 100.0f : 50.0f;
                c.mask({x, y, z}) = (r > 9 && r <= 12) || c.rod({x, y, z});
            }
    return c;
}

// Checks a cut's result: genus 0 with one piece and the shell's one cavity, nothing added, and at
// least one voxel removed, every one of them on the rod.
inline void expect_rod_cut(const RodShell& c, const Grid<std::uint8_t>& after) {
    const Topology t = mask_topology(after);
    EXPECT_EQ(t.genus, 0);
    EXPECT_EQ(t.components, 1u);
    EXPECT_EQ(t.cavities, 1u);
    std::size_t removed = 0;
    for (PointIndex i = 0; i < after.size(); ++i) {
        EXPECT_FALSE(after[i] && !c.mask[i]);
        if (c.mask[i] && !after[i]) {
            ++removed;
            EXPECT_TRUE(c.rod[i]) << "removed a voxel off the handle";
        }
    }
    EXPECT_GE(removed, 1u);
}

}  // namespace liveset::testing
