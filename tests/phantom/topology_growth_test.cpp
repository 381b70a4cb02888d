// Simple-point test and topology-preserving growth, checked against mask_topology on hand-made
// configurations: a voxel that would join two pieces, close a ring or seal a cavity is refused.
#include <gtest/gtest.h>

#include <vector>

#include "liveset/eval/topology.hpp"
#include "liveset/phantom/topology_growth.hpp"

namespace liveset {
namespace {

struct Box {
    Lattice lattice{Vec3i{9, 9, 9}, Vec3d{1, 1, 1}, Vec3d{0, 0, 0}};
    std::vector<std::uint8_t> set = std::vector<std::uint8_t>(lattice.size(), 0);
    void add(Vec3i p) { set[lattice.index(p)] = 1; }
    Topology topology() const {
        Grid<std::uint8_t> g(lattice, 0);
        for (PointIndex i = 0; i < lattice.size(); ++i) g[i] = set[i];
        return mask_topology(g);
    }
};

// Reference: does adding p change the components, cavities or genus that mask_topology counts?
bool changes_topology(Box b, Vec3i p) {
    const Topology before = b.topology();
    b.add(p);
    const Topology after = b.topology();
    return before.components != after.components || before.cavities != after.cavities || before.genus != after.genus;
}

TEST(TopologyGrowth, SimplePointsAgreeWithTheTopologyCount) {
    // A ring of 8 voxels around (4,4,4) in the z = 4 plane, with one gap at (5,4,4).
    Box ring;
    for (Vec3i p : {Vec3i{3, 3, 4}, Vec3i{4, 3, 4}, Vec3i{5, 3, 4}, Vec3i{3, 4, 4}, Vec3i{3, 5, 4}, Vec3i{4, 5, 4}, Vec3i{5, 5, 4}})
        ring.add(p);
    EXPECT_FALSE(is_simple_addition(ring.lattice, ring.set, {5, 4, 4}));  // closes the ring: a tunnel
    EXPECT_TRUE(changes_topology(ring, {5, 4, 4}));
    EXPECT_TRUE(is_simple_addition(ring.lattice, ring.set, {2, 3, 4}));  // extends it
    EXPECT_FALSE(changes_topology(ring, {2, 3, 4}));
    EXPECT_FALSE(is_simple_addition(ring.lattice, ring.set, {7, 7, 7}));  // a new component
    EXPECT_TRUE(changes_topology(ring, {7, 7, 7}));

    // Two voxels two apart: the one between them joins two components.
    Box pair;
    pair.add({2, 4, 4});
    pair.add({4, 4, 4});
    EXPECT_FALSE(is_simple_addition(pair.lattice, pair.set, {3, 4, 4}));
    EXPECT_TRUE(changes_topology(pair, {3, 4, 4}));

    // A hollow 3x3x3 cube missing one face centre: filling it seals a cavity.
    Box hollow;
    for (int z = 3; z <= 5; ++z)
        for (int y = 3; y <= 5; ++y)
            for (int x = 3; x <= 5; ++x)
                if (Vec3i{x, y, z} != Vec3i{4, 4, 4} && Vec3i{x, y, z} != Vec3i{4, 4, 5}) hollow.add({x, y, z});
    EXPECT_FALSE(is_simple_addition(hollow.lattice, hollow.set, {4, 4, 5}));
    EXPECT_TRUE(changes_topology(hollow, {4, 4, 5}));

    // Every voxel of the lattice against one random-ish configuration: the test and the count agree.
    Box mixed;
    for (PointIndex i = 0; i < mixed.lattice.size(); ++i) {
        const Vec3i c = mixed.lattice.coord(i);
        if (c.x == 0 || c.y == 0 || c.z == 0 || c.x == 8 || c.y == 8 || c.z == 8) continue;
        if (((i * 2654435761u) >> 7) % 3 == 0) mixed.set[i] = 1;
    }
    int checked = 0;
    for (PointIndex i = 0; i < mixed.lattice.size(); ++i) {
        const Vec3i c = mixed.lattice.coord(i);
        if (mixed.set[i] || c.x == 0 || c.y == 0 || c.z == 0 || c.x == 8 || c.y == 8 || c.z == 8) continue;
        const bool simple = is_simple_addition(mixed.lattice, mixed.set, c);
        // A simple addition never changes the topology (the converse needs the local reading).
        if (simple) {
            EXPECT_FALSE(changes_topology(mixed, c)) << c.x << "," << c.y << "," << c.z;
        }
        ++checked;
    }
    EXPECT_GT(checked, 100);
}

TEST(TopologyGrowth, GrowingIntoATorusKeepsABall) {
    // Allowed: a thick square torus in z = 3..5 around a hole at x, y = 4; grown from one voxel.
    Box allowed, region;
    for (int z = 3; z <= 5; ++z)
        for (int y = 2; y <= 6; ++y)
            for (int x = 2; x <= 6; ++x)
                if (!(x == 4 && y == 4)) allowed.add({x, y, z});
    const Topology torus = allowed.topology();
    ASSERT_EQ(torus.genus, 1);
    region.add({2, 2, 3});
    grow_preserving_topology(region.lattice, region.set, allowed.set, [](Vec3i c) { return c.x + c.y + 0.1 * c.z; });
    const Topology grown = region.topology();
    EXPECT_EQ(grown.components, 1u);
    EXPECT_EQ(grown.cavities, 0u);
    EXPECT_EQ(grown.genus, 0);
    std::size_t in = 0, total = 0;
    for (PointIndex i = 0; i < region.lattice.size(); ++i) {
        EXPECT_TRUE(!region.set[i] || allowed.set[i]);
        in += region.set[i];
        total += allowed.set[i];
    }
    EXPECT_LT(in, total);           // something was refused to cut the ring
    EXPECT_GE(in + 6, total);       // but only one cross-section of an arm (2 x 3 voxels)
}

}  // namespace
}  // namespace liveset
