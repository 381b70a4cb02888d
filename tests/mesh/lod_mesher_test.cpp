// LodMesher: the coarse level of detail equals marching cubes of the brute-force k-subsampled φ
// (built from scratch) after every incremental update driven by the fine mesher's U, for k = 2 and
// 3 on lattice sizes that are and are not multiples of k, and its vertices, mapped back to fine
// index space (x k), lie on the sphere.
#include <gtest/gtest.h>

#include <cmath>

#include "liveset/mesh/fragment_mesher.hpp"
#include "liveset/mesh/lod_mesher.hpp"
#include "liveset/mesh/mesh_analysis.hpp"
#include "mesh_test_fields.hpp"

namespace liveset {
namespace {

Grid<float> subsampled(const Grid<float>& phi, int k) {
    Grid<float> c{coarsened(phi.lattice(), k)};
    const Vec3i d = c.lattice().dims();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) c({x, y, z}) = phi({k * x, k * y, k * z});
    return c;
}

void expect_matches_brute_force(const LodMesher& lod, const Grid<float>& phi) {
    const Grid<float> c = subsampled(phi, lod.factor());
    ASSERT_EQ(c.values().size(), lod.phi().values().size());
    for (std::size_t i = 0; i < c.values().size(); ++i) ASSERT_EQ(c.values()[i], lod.phi().values()[i]) << "point " << i;
    FragmentMesher fresh(c.lattice(), lod.mesher().fragment_size());
    fresh.full_rebuild(c);
    ASSERT_GT(fresh.triangle_count(), 0u);
    EXPECT_EQ(canonical_triangles(lod.mesher().merged()), canonical_triangles(fresh.merged()));
}

TEST(LodMesher, CoarseLatticeHasTwiceTheSpacingAndTheSameOriginAndDirection) {
    const Lattice fine({37, 20, 9}, {0.5, 1.0, 2.0}, {3.0, -4.0, 5.0});
    const Lattice c = coarsened(fine, 2);
    EXPECT_EQ(c.dims(), (Vec3i{19, 10, 5}));
    for (const Vec3i p : {Vec3i{0, 0, 0}, Vec3i{18, 9, 4}, Vec3i{5, 3, 2}}) {
        const Vec3d a = c.to_world(p.cast<double>()), b = fine.to_world((2 * p).cast<double>());
        EXPECT_NEAR(norm(a - b), 0.0, 1e-12) << p;
    }
    const Lattice c3 = coarsened(fine, 3);
    EXPECT_EQ(c3.dims(), (Vec3i{13, 7, 3}));
    EXPECT_NEAR(norm(c3.to_world({12, 6, 2}) - fine.to_world({36, 18, 6})), 0.0, 1e-12);
    EXPECT_THROW(coarsened(fine, 1), std::invalid_argument);
}

TEST(LodMesher, IncrementalUpdatesFromTheFineFragmentsEqualTheSubsampledSurfaceBuiltFromScratch) {
    for (const auto& [dims, k] : {std::pair{Vec3i{40, 36, 33}, 2}, std::pair{Vec3i{41, 37, 34}, 2}, std::pair{Vec3i{39, 36, 33}, 3},
                                  std::pair{Vec3i{41, 37, 35}, 3}}) {
        Grid<float> phi = testing::sphere_field(dims, {18.0, 17.0, 16.0}, 9.0);
        FragmentMesher fine(phi.lattice(), 6);
        fine.full_rebuild(phi);
        LodMesher lod(phi.lattice(), 6, k);
        lod.rebuild(phi);
        expect_matches_brute_force(lod, phi);
        // Grow the sphere step by step in a moving box; each step's X goes through the fine mesher.
        for (int step = 1; step <= 4; ++step) {
            const Grid<float> next = testing::sphere_field(dims, {18.0 + step, 17.0, 16.0 + 0.5 * step}, 9.0 + 1.5 * step);
            std::vector<PointIndex> changed;
            for (PointIndex i = 0; i < phi.values().size(); ++i) {
                const Vec3i p = phi.lattice().coord(i);
                if (p.x >= 4 + 3 * step && p.x < 40 - step && phi.values()[i] != next.values()[i]) {
                    phi.values()[i] = next.values()[i];
                    changed.push_back(i);
                }
            }
            const std::vector<FragmentId> u = fine.update(phi, changed);
            ASSERT_FALSE(u.empty());
            const std::vector<FragmentId> cu = lod.update(phi, fine, u);
            EXPECT_FALSE(cu.empty());
            EXPECT_TRUE(std::is_sorted(cu.begin(), cu.end()));
            expect_matches_brute_force(lod, phi);
        }
    }
}

// refresh(φ) needs no fine mesher (a background run defers it) and reports the coarse fragments a
// fragment-driven update would: the same surface as built from scratch after each step.
TEST(LodMesher, RefreshWithoutTheFineMesherEqualsTheFragmentDrivenUpdate) {
    const Vec3i dims{41, 37, 35};
    Grid<float> phi = testing::sphere_field(dims, {18.0, 17.0, 16.0}, 9.0);
    FragmentMesher fine(phi.lattice(), 6);
    fine.full_rebuild(phi);
    LodMesher by_fragments(phi.lattice(), 6, 3), by_refresh(phi.lattice(), 6, 3);
    by_fragments.rebuild(phi);
    EXPECT_EQ(by_refresh.refresh(phi).size(), by_refresh.mesher().fragment_count());  // first call: everything
    expect_matches_brute_force(by_refresh, phi);
    EXPECT_TRUE(by_refresh.refresh(phi).empty());  // nothing changed
    for (int step = 1; step <= 3; ++step) {
        const Grid<float> next = testing::sphere_field(dims, {18.0 + step, 17.0, 16.0}, 9.0 + 2.0 * step);
        std::vector<PointIndex> changed;
        for (PointIndex i = 0; i < phi.values().size(); ++i)
            if (phi.values()[i] != next.values()[i]) {
                phi.values()[i] = next.values()[i];
                changed.push_back(i);
            }
        const std::vector<FragmentId> a = by_fragments.update(phi, fine, fine.update(phi, changed));
        const std::vector<FragmentId> b = by_refresh.refresh(phi);
        EXPECT_EQ(a, b) << "step " << step;
        expect_matches_brute_force(by_refresh, phi);
    }
    EXPECT_THROW(by_refresh.refresh(Grid<float>{Lattice({24, 20, 20})}), std::invalid_argument);
}

TEST(LodMesher, CoarseVerticesMappedToFineIndexSpaceLieOnTheSphere) {
    const Grid<float> phi = testing::sphere_field({48, 48, 48}, {23.5, 24.0, 23.0}, 15.0);
    LodMesher lod(phi.lattice(), 16);
    lod.rebuild(phi);
    const Mesh m = lod.mesher().merged();
    ASSERT_GT(m.triangle_count(), 500u);
    for (const Vertex& v : m.vertices) {
        const Vec3d p{2.0 * v.position[0] - 23.5, 2.0 * v.position[1] - 24.0, 2.0 * v.position[2] - 23.0};
        EXPECT_NEAR(norm(p), 15.0, 0.25);  // linear interpolation of a distance along 2-voxel edges
    }
}

TEST(LodMesher, RefusesAFieldOfOtherDimensions) {
    LodMesher lod(Lattice({20, 20, 20}), 8);
    EXPECT_THROW(lod.rebuild(Grid<float>{Lattice({24, 20, 20})}), std::invalid_argument);
    FragmentMesher fine(Lattice({24, 20, 20}), 8);
    EXPECT_THROW(lod.update(Grid<float>{Lattice({24, 20, 20})}, fine, {}), std::invalid_argument);
}

}  // namespace
}  // namespace liveset
