// Lattice geometry: indexing round trips, world mapping with spacing/origin/direction, validation.
#include <gtest/gtest.h>

#include <cmath>

#include "liveset/grid/grid.hpp"

using namespace liveset;

TEST(Lattice, IndexCoordRoundTrip) {
    const Lattice lat({7, 5, 3});
    EXPECT_EQ(lat.size(), 105u);
    for (PointIndex i = 0; i < lat.size(); ++i) EXPECT_EQ(lat.index(lat.coord(i)), i);
    EXPECT_EQ(lat.index({1, 2, 1}), 1u + 7u * 2u + 35u);
}

TEST(Lattice, WorldMappingWithSpacingOriginAndDirection) {
    // 90 degrees about z: index x -> world y, index y -> world -x.
    const Mat3d rot{0, -1, 0, 1, 0, 0, 0, 0, 1};
    const Lattice lat({10, 10, 10}, {0.5, 2.0, 3.0}, {10, 20, 30}, rot);
    const Vec3d w = lat.to_world({2, 1, 1});
    EXPECT_NEAR(w.x, 10 - 2.0, 1e-12);  // -y*2
    EXPECT_NEAR(w.y, 20 + 1.0, 1e-12);  // x*0.5
    EXPECT_NEAR(w.z, 30 + 3.0, 1e-12);
    const Vec3d back = lat.to_index(w);
    EXPECT_NEAR(back.x, 2, 1e-12);
    EXPECT_NEAR(back.y, 1, 1e-12);
    EXPECT_NEAR(back.z, 1, 1e-12);
    // A gradient along index x maps to world +y (direction cosine), unit length.
    const Vec3d n = lat.direction_to_world({1, 0, 0});
    EXPECT_NEAR(n.y, 1.0, 1e-12);
    EXPECT_NEAR(norm(n), 1.0, 1e-12);
}

TEST(Lattice, RejectsInvalidGeometry) {
    EXPECT_THROW(Lattice({0, 4, 4}), std::invalid_argument);
    EXPECT_THROW(Lattice({4, -1, 4}), std::invalid_argument);
    EXPECT_THROW(Lattice({1 << 20, 1 << 20, 1 << 20}), std::invalid_argument);
    EXPECT_THROW(Lattice({4, 4, 4}, {1, 0, 1}), std::invalid_argument);
    EXPECT_THROW(Lattice({4, 4, 4}, {1, NAN, 1}), std::invalid_argument);
    // Sizes that float cannot hold or invert (the curvature's 1/spacing is a float) are refused;
    // a micrometre and a metre are not.
    EXPECT_THROW(Lattice({4, 4, 4}, {1, 1e-46, 1}), std::invalid_argument);
    EXPECT_THROW(Lattice({4, 4, 4}, {1e300, 1, 1}), std::invalid_argument);
    EXPECT_NO_THROW(Lattice({4, 4, 4}, {1e-3, 1e3, 1}));
    EXPECT_THROW(Lattice({4, 4, 4}, {1, 1, 1}, {0, INFINITY, 0}), std::invalid_argument);
    EXPECT_THROW(Lattice({4, 4, 4}, {1, 1, 1}, {0, 0, 0}, Mat3d{1, 0, 0, 1, 0, 0, 0, 0, 1}), std::invalid_argument);
}

TEST(Grid, ClampedAndCheckedAccess) {
    Grid<int> g(Lattice({3, 3, 3}), 0);
    g({2, 2, 2}) = 7;
    EXPECT_EQ(g.clamped({5, 9, 3}), 7);
    EXPECT_THROW(g.at({3, 0, 0}), std::out_of_range);
}
