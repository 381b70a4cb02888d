// Canonical axis order: every voxel keeps its world position and value, round trips are exact, and
// lattices that differ only in storage order reach the same canonical lattice.
#include <gtest/gtest.h>

#include "liveset/grid/reorient.hpp"

using namespace liveset;

namespace {

// An oblique lattice (rotated ~20° about z), anisotropic, off-centre; values = their own index.
Grid<float> numbered() {
    const double c = 0.94, s = 0.342;
    Grid<float> g(Lattice({5, 7, 4}, {1.1, 0.9, 1.3}, {-3.0, 12.5, 40.0}, {c, -s, 0, s, c, 0, 0, 0, 1}));
    for (std::size_t i = 0; i < g.size(); ++i) g[static_cast<PointIndex>(i)] = static_cast<float>(i);
    return g;
}

void expect_same_world_values(const Grid<float>& a, const Grid<float>& b) {
    // Every voxel of `b` sits where the voxel of `a` with the same value sits.
    for (std::size_t i = 0; i < b.size(); ++i) {
        const Vec3i pb = b.lattice().coord(static_cast<PointIndex>(i));
        const Vec3i pa = a.lattice().coord(static_cast<PointIndex>(b[static_cast<PointIndex>(i)]));
        const Vec3d wa = a.lattice().to_world({double(pa.x), double(pa.y), double(pa.z)});
        const Vec3d wb = b.lattice().to_world({double(pb.x), double(pb.y), double(pb.z)});
        ASSERT_LT(norm(wa - wb), 1e-9) << i;
    }
}

}  // namespace

TEST(Reorient, EveryPermutationAndFlipKeepsEachVoxelInPlace) {
    const Grid<float> g = numbered();
    for (const std::array<int, 3> axis : {std::array{0, 1, 2}, {1, 0, 2}, {2, 0, 1}, {2, 1, 0}})
        for (int f = 0; f < 8; ++f) {
            AxisOrder o;
            o.axis = axis;
            o.flip = {(f & 1) != 0, (f & 2) != 0, (f & 4) != 0};
            const Grid<float> r = reorder(g, o);
            expect_same_world_values(g, r);
            const Grid<float> back = restore(r, o, g.lattice());
            for (std::size_t i = 0; i < g.size(); ++i) ASSERT_EQ(back[static_cast<PointIndex>(i)], g[static_cast<PointIndex>(i)]);
            // Stored any way, the image reaches one canonical array.
            const Grid<float> c1 = reorder(g, canonical_order(g.lattice()));
            const Grid<float> c2 = reorder(r, canonical_order(r.lattice()));
            ASSERT_EQ(c1.dims(), c2.dims());
            for (std::size_t i = 0; i < c1.size(); ++i) ASSERT_EQ(c1[static_cast<PointIndex>(i)], c2[static_cast<PointIndex>(i)]);
            EXPECT_LT(norm(c1.lattice().origin() - c2.lattice().origin()), 1e-9);
        }
}

TEST(Reorient, TheCanonicalOrderOfAnLpsLatticeIsTheIdentity) {
    EXPECT_TRUE(canonical_order(numbered().lattice()).identity());
    const Lattice ras({4, 4, 4}, {1, 1, 1}, {0, 0, 0}, {-1, 0, 0, 0, -1, 0, 0, 0, 1});
    const AxisOrder o = canonical_order(ras);
    EXPECT_EQ(o.axis, (std::array<int, 3>{0, 1, 2}));
    EXPECT_EQ(o.flip, (std::array<bool, 3>{true, true, false}));
}
