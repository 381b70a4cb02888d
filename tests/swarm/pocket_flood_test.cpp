// The pocket flood against brute force: on random masks, whether some voxels just flipped inside
// separate a small region of the outside off, from a full 6-connected labelling of the outside.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <random>
#include <set>
#include <vector>

#include "liveset/eval/topology.hpp"
#include "liveset/swarm/pocket_flood.hpp"

namespace liveset {
namespace {

// The definition: the starts lie in two or more outside regions, and one of those holds at most
// `limit` voxels and touches no border voxel.
bool seals_by_labelling(const Grid<std::uint8_t>& inside, const std::vector<Vec3i>& starts, std::size_t limit) {
    const Lattice& lat = inside.lattice();
    Grid<std::uint8_t> outside(lat, 0);
    for (PointIndex i = 0; i < lat.size(); ++i) outside[i] = inside[i] ? 0 : 1;
    const ComponentLabels label = label_components(outside, 6, nullptr);
    std::map<std::uint32_t, std::size_t> size;
    std::set<std::uint32_t> on_border;
    const Vec3i d = lat.dims();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) {
                const std::uint32_t l = label[lat.index({x, y, z})];
                if (l == 0) continue;
                ++size[l];
                if (x == 0 || y == 0 || z == 0 || x == d.x - 1 || y == d.y - 1 || z == d.z - 1) on_border.insert(l);
            }
    std::set<std::uint32_t> regions;
    for (const Vec3i s : starts) regions.insert(label[lat.index(s)]);
    if (regions.size() < 2) return false;
    return std::any_of(regions.begin(), regions.end(), [&](std::uint32_t l) { return size[l] <= limit && !on_border.count(l); });
}

// Random masks (a density per trial, so both sparse and dense insides), a few random inside
// voxels as the flipped ones, their outside face neighbours as the starts; several limits, one
// PocketFlood reused for every call (its marks carry over). Both answers occur many times.
TEST(PocketFlood, MatchesTheLabellingOfTheOutside) {
    const Lattice lat({11, 10, 9});
    std::mt19937 rng(7);
    PocketFlood flood;
    int seals = 0, not_seals = 0;
    for (int trial = 0; trial < 600; ++trial) {
        const double density = 0.25 + 0.5 * std::uniform_real_distribution<double>(0, 1)(rng);
        Grid<std::uint8_t> inside(lat, 0);
        for (PointIndex i = 0; i < lat.size(); ++i) inside[i] = std::uniform_real_distribution<double>(0, 1)(rng) < density;
        const int flipped = 1 + trial % 4;
        std::vector<Vec3i> starts;
        for (int k = 0; k < flipped; ++k) {
            const Vec3i c{std::uniform_int_distribution<int>(0, 10)(rng), std::uniform_int_distribution<int>(0, 9)(rng),
                          std::uniform_int_distribution<int>(0, 8)(rng)};
            inside(c) = 1;
            for (int f = 0; f < 6; ++f) {
                Vec3i q = c;
                q[f / 2] += (f % 2) ? 1 : -1;
                if (lat.contains(q)) starts.push_back(q);
            }
        }
        std::erase_if(starts, [&](Vec3i q) { return inside(q) != 0; });
        const auto outside_at = [&](PointIndex i) { return inside[i] == 0; };
        for (const std::size_t limit : {std::size_t{0}, std::size_t{1}, std::size_t{3}, std::size_t{12}, std::size_t{200}}) {
            const bool expected = seals_by_labelling(inside, starts, limit);
            ASSERT_EQ(flood.seals(lat, outside_at, starts, limit), expected) << "trial " << trial << " limit " << limit;
            (expected ? seals : not_seals) += 1;
        }
    }
    EXPECT_GT(seals, 100);
    EXPECT_GT(not_seals, 100);
}

// The case that motivated turning the floods together: a ring of four inside voxels around an
// outside voxel c, in a closed cavity of 7³. Flipping c closes the ring's tunnel; its outside
// neighbours on the two sides of the ring join around it inside the cavity, so nothing is
// separated — however small the cavity. With the ring's two sides walled apart (a plate through
// the cavity at c's x), the side of fewer voxels is a pocket exactly up to its size.
TEST(PocketFlood, PiecesThatJoinAroundTheFlipAreNoPocket) {
    const Lattice lat({13, 13, 13});
    Grid<std::uint8_t> inside(lat, 1);
    for (int z = 3; z < 10; ++z)
        for (int y = 3; y < 10; ++y)
            for (int x = 3; x < 10; ++x) inside({x, y, z}) = 0;  // the cavity, 343 voxels
    const Vec3i c{6, 6, 6};
    for (const Vec3i r : {Vec3i{6, 5, 6}, Vec3i{6, 7, 6}, Vec3i{6, 6, 5}, Vec3i{6, 6, 7}}) inside(r) = 1;
    inside(c) = 1;
    const std::vector<Vec3i> starts{{5, 6, 6}, {7, 6, 6}};
    const auto outside_at = [&](PointIndex i) { return inside[i] == 0; };
    PocketFlood flood;
    for (const std::size_t limit : {std::size_t{10}, std::size_t{338}, std::size_t{100000}})
        EXPECT_FALSE(flood.seals(lat, outside_at, starts, limit)) << limit;
    for (int z = 3; z < 10; ++z)
        for (int y = 3; y < 10; ++y) inside({6, y, z}) = 1;  // the plate: 3 x 7 x 7 = 147 voxels each side
    EXPECT_FALSE(flood.seals(lat, outside_at, starts, 146));
    EXPECT_TRUE(flood.seals(lat, outside_at, starts, 147));
    EXPECT_EQ(flood.seals(lat, outside_at, starts, 147), seals_by_labelling(inside, starts, 147));
}

}  // namespace
}  // namespace liveset
